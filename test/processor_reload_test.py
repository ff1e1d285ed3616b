#!/usr/bin/env python3
"""~reload with a good and a bad parameter file: a good file swaps the model (visible on ~model and
in the output's K), a bad one is refused with a message naming the key and the old model stays."""
import math
import os
import shutil
import sys
import time
import unittest

import rospy
import rostest
from std_srvs.srv import Trigger

from hrg_gyro.msg import ChannelAmplitudes, GyroOutput, ModelInfo

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402


def channels(seq, t, theta):
    """Ideal channel amplitudes (docs/math.md, 'Channel amplitudes') of A = 1, B = 0.02, tau = 0.3."""
    a, b, tau = 1.0, 0.02, 0.3
    m = ChannelAmplitudes()
    m.header.seq = seq
    m.header.stamp = rospy.Time.from_sec(t)
    ct, st, cp, sp = math.cos(theta), math.sin(theta), math.cos(tau), math.sin(tau)
    m.c_in = a * ct * cp - b * st * sp
    m.c_quad = -a * ct * sp - b * st * cp
    m.s_in = a * st * cp + b * ct * sp
    m.s_quad = -a * st * sp + b * ct * cp
    m.frequency = 5000.0
    m.temperature = float("nan")
    m.periods = 25
    return m


class Reload(unittest.TestCase):
    def setUp(self):
        self.file = rospy.get_param("~parameter_file")
        self.template = rospy.get_param("~template")
        shutil.copy(self.template, self.file)
        self.pub = rospy.Publisher("/channels", ChannelAmplitudes, queue_size=100)
        self.outputs = util.Latest("/output", GyroOutput)
        self.model = util.Latest("/processor/model", ModelInfo)
        util.wait_for_service("/processor/reload")
        self.reload = rospy.ServiceProxy("/processor/reload", Trigger)
        util.wait_for(lambda: self.pub.get_num_connections() > 0, "the processor to subscribe")
        self.seq = 0
        self.t = time.time()

    def feed(self, n):
        for _ in range(n):
            self.seq += 1
            self.t += 0.005
            self.pub.publish(channels(self.seq, self.t, 0.2 - 0.028 * (self.t % 100)))
            time.sleep(0.005)

    def test_good_then_bad_file(self):
        util.wait_for(lambda: self.model.msg, "~model")
        self.assertEqual(self.model.msg.calibration_method, "none")
        self.feed(20)
        util.wait_for(lambda: self.outputs.msg, "an output")
        self.assertAlmostEqual(self.outputs.msg.scale_factor, -0.56, places=12)

        # A good file with another K0 and provenance.
        text = open(self.template).read().replace("mean: -0.56 ", "mean: -0.57 ").replace("method: none", "method: manual")
        with open(self.file, "w") as f:
            f.write(text)
        r = self.reload()
        self.assertTrue(r.success, r.message)
        self.assertIn("-0.57", r.message)
        util.wait_for(lambda: self.model.msg.calibration_method == "manual", "~model after reload")
        self.assertGreater(self.model.msg.header.stamp.to_sec(), 0.0)
        self.feed(20)
        util.wait_for(lambda: abs(self.outputs.msg.scale_factor + 0.57) < 1e-12, "outputs with the new K0")

        # A bad file: an odd harmonic order. Refused, named, old model kept.
        with open(self.file, "w") as f:
            f.write(text.replace("orders: [2, 4, 6, 8]", "orders: [2, 3, 6, 8]"))
        r = self.reload()
        self.assertFalse(r.success)
        self.assertIn("scale_factor.orders[1]", r.message)
        self.assertIn("odd", r.message)
        # A truncated file.
        with open(self.file, "w") as f:
            f.write(text[: len(text) // 3])
        r = self.reload()
        self.assertFalse(r.success)
        self.assertIn("kept the previous model", r.message)
        self.feed(20)
        time.sleep(0.5)
        self.assertAlmostEqual(self.outputs.msg.scale_factor, -0.57, places=12)
        self.assertEqual(self.model.msg.calibration_method, "manual")
        # An unreadable path, then recovery.
        os.remove(self.file)
        self.assertFalse(self.reload().success)
        shutil.copy(self.template, self.file)
        self.assertTrue(self.reload().success)


if __name__ == "__main__":
    rospy.init_node("processor_reload_test")
    rostest.rosrun("hrg_gyro", "processor_reload", Reload)
