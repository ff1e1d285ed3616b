#!/usr/bin/env python3
"""~capture_bias: at rest, D0 is refreshed so that the output averages the vertical Earth rate
of the model's latitude, the file is rewritten with a backup and the new model is published (a
second capture leaves one note, of the latest, in the file); while the table turns, the capture is
refused and nothing changes."""
import math
import os
import shutil
import sys
import unittest

import rospy
import rostest
import yaml
from std_srvs.srv import Trigger

from hrg_gyro.msg import GyroOutput, ModelInfo, TurntableState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

EARTH = 7.2921150e-5 * math.sin(0.9)  # the parameter file's latitude


class BiasCapture(unittest.TestCase):
    def mean_rate(self, out, seconds):
        """Mean output rate over the next `seconds` of sim time, from the integrated angle alpha of the
        first and last outputs (exact whatever this subscriber may have missed in between)."""
        start = rospy.get_time()
        first = out.count
        util.wait_for(lambda: rospy.get_time() > start + seconds, "%.0f s of sim time" % seconds)
        a, b = out.all[first], out.all[-1]
        return (b.alpha - a.alpha) / (b.header.stamp - a.header.stamp).to_sec()

    def test_capture_at_rest_then_refused_while_turning(self):
        path = rospy.get_param("~parameter_file")
        # Start from the uncalibrated model whatever an earlier run left in the work directory.
        shutil.copy(rospy.get_param("~template"), path)
        util.wait_for_service("/gyro/processor/reload")
        self.assertTrue(rospy.ServiceProxy("/gyro/processor/reload", Trigger)().success)
        out = util.Latest("/gyro/output", GyroOutput, keep_all=True)
        models = util.Latest("/gyro/processor/model", ModelInfo, keep_all=True)
        # The session starts once this test listens to the table (the driver waits for it): the
        # steps below then have the whole rest, however late this node started.
        util.wait_for(lambda: out.sub.get_num_connections() > 0, "this test's connection to the outputs")
        table = util.Latest("/gyro/turntable/state", TurntableState)
        util.wait_for(lambda: out.count > 100 and models.count >= 1, "outputs")
        # The simulated gyro's white angle noise (about 9e-6 rad per output) leaves sqrt(2) 9e-6 / T on
        # a mean rate over T seconds: 1.3e-6 rad/s over 10 s, 6e-7 over 20 s (capture and check alike).
        before = self.mean_rate(out, 10.0)
        self.assertGreater(abs(before - EARTH), 2e-5, "the uncalibrated D0 should leave a visible bias")

        util.wait_for_service("/gyro/processor/capture_bias")
        capture = rospy.ServiceProxy("/gyro/processor/capture_bias", Trigger)
        r = capture()
        self.assertTrue(r.success, r.message)
        self.assertIn("D0", r.message)
        self.assertIn("written to", r.message)
        after = self.mean_rate(out, 20.0)
        self.assertLess(abs(after - EARTH), 4e-6, "mean rate %.3e rad/s, Earth %.3e (before %.3e)" % (after, EARTH, before))
        rospy.loginfo("bias capture: mean rate before %.4e, after %.4e rad/s, Earth %.4e", before, after, EARTH)
        util.wait_for(lambda: models.count >= 2, "the new model on ~model")
        with open(path) as f:
            written = yaml.safe_load(f)
        self.assertNotEqual(written["drift"]["mean"], 0.0)
        self.assertIn("bias capture", written["calibration"]["notes"])
        self.assertTrue(os.path.exists(path + ".bak"))
        with open(path + ".bak") as f:
            self.assertEqual(yaml.safe_load(f)["drift"]["mean"], 0.0)
        # A second capture (the rest lasts 120 s, this ends near 71 s of session time plus what this
        # node's own steps took): the notes name the latest capture once instead of growing a line
        # per capture.
        r = capture()
        self.assertTrue(r.success, r.message)
        with open(path) as f:
            notes = yaml.safe_load(f)["calibration"]["notes"]
        self.assertEqual(notes.count("turn-on bias capture"), 1, notes)

        # Now the table turns: the capture is refused and the file stays as it is.
        util.wait_for(lambda: table.msg and abs(table.msg.rate) > 0.04, "the table to turn")
        with open(path) as f:
            text = f.read()
        r = capture()
        self.assertFalse(r.success, r.message)
        self.assertIn("refused", r.message)
        with open(path) as f:
            self.assertEqual(f.read(), text)


if __name__ == "__main__":
    rospy.init_node("bias_capture_test")
    rostest.rosrun("hrg_gyro", "bias_capture", BiasCapture)
