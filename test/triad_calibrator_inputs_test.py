#!/usr/bin/env python3
"""The calibrator in triad mode on bad live input (test/triad_calibrator_inputs.test): axes x and y
and the table deliver, axis z never does; some wave angles are NaN, some fixture quaternions are no
rotation, some stamps are zero or go back. The node stays up, its diagnostic counts each kind and
warns about the silent axis, ~start refuses a single-axis method and a second run, and ~finish
refuses the run with the missing axis named: a report is written, the parameter files are not."""
import math
import os
import sys
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Quaternion
from std_srvs.srv import Trigger

from hrg_gyro.msg import FixturePosition, TriadCalibrationResult, TurntableState, WaveState
from hrg_gyro.srv import StartCalibration

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

T0 = 1000.0  # s, the stamps of the synthetic session (the calibrator reads header stamps only)
RATE = 100.0  # Hz


class TriadInputs(unittest.TestCase):
    def setUp(self):
        self.work = rospy.get_param("~work_dir")
        self.status = None
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics)
        self.result = util.Latest("/calibrator/result", TriadCalibrationResult)
        self.waves = [rospy.Publisher("/%s/wave" % a, WaveState, queue_size=5000) for a in ("x", "y")]
        self.table = rospy.Publisher("/turntable/state", TurntableState, queue_size=5000)
        self.fixture = rospy.Publisher("/fixture/position", FixturePosition, queue_size=100)
        for p in self.waves + [self.table, self.fixture]:
            util.wait_for(lambda: p.get_num_connections() > 0, "the calibrator to subscribe to " + p.name)

    def on_diagnostics(self, msg):
        for s in msg.status:
            if s.name.endswith("triad calibration"):
                self.status = (s.level, s.message, dict((kv.key, kv.value) for kv in s.values))

    def stamp(self, k):
        return rospy.Time.from_sec(T0 + k / RATE)

    def publish_session(self, seconds):
        """Axes x and y, the table at rest and the fixture (+z up, locked) once a second, with faults."""
        n = int(seconds * RATE)
        for k in range(n):
            t = self.stamp(k)
            if k % int(RATE) == 0:
                f = FixturePosition()
                f.header.stamp = t
                f.index, f.name, f.locked = 0, "z up", True
                # every third record's quaternion is no rotation (norm 1.1): dropped, counted
                f.body_to_table = Quaternion(0, 0, 0, 1.1 if (k // int(RATE)) % 3 == 2 else 1.0)
                self.fixture.publish(f)
            s = TurntableState()
            s.header.stamp, s.header.seq = t, k
            s.angle, s.rate = 0.0, 0.0
            self.table.publish(s)
            for i, pub in enumerate(self.waves):
                w = WaveState()
                w.header.stamp = t
                w.theta = float("nan") if (i == 0 and k % 50 == 7) else 0.1 * i + 1e-6 * k
                w.frequency = float("nan")
                pub.publish(w)
            if k == n // 2:
                late = WaveState()  # 3 s behind y's previous record: beyond backward_reset, a stamp jump, dropped
                late.header.stamp = self.stamp(0)
                late.theta = 0.0
                self.waves[1].publish(late)
                zero = TurntableState()  # a zero stamp
                self.table.publish(zero)
            time.sleep(0.5 / RATE)

    def test_bad_input_is_counted_and_the_missing_axis_named(self):
        seconds = 6.0
        self.publish_session(seconds)
        nan_thetas = len([k for k in range(int(seconds * RATE)) if k % 50 == 7])
        bad_fixtures = len([s for s in range(int(seconds)) if s % 3 == 2])

        def counted():
            if not self.status:
                return False
            v = self.status[2]
            return (v.get("axis x dropped (non-finite theta)") == str(nan_thetas)
                    and v.get("fixture dropped (orientation not a rotation)") == str(bad_fixtures)
                    and v.get("axis y dropped (stamp jump)") == "1"
                    and v.get("turntable dropped (zero stamp)") == "1")
        util.wait_for(counted, "the diagnostic to count the bad records (last: %r)" % (self.status,))
        level, message, values = self.status
        self.assertEqual(level, 1, message)  # WARN
        self.assertIn("no wave from axis z", message)
        self.assertEqual(values["axis z received"], "0")
        self.assertEqual(values["run"], "running")
        self.assertIn("'z up' locked", values["fixture position"])
        self.assertEqual(values["axes along the table axis so far"], "z")

        start = rospy.ServiceProxy("/calibrator/start", StartCalibration)
        r = start("dual_rate")
        self.assertFalse(r.success)
        self.assertIn("triad", r.message)
        r = start("")
        self.assertFalse(r.success)
        self.assertIn("in progress", r.message)

        finish = rospy.ServiceProxy("/calibrator/finish", Trigger)
        r = finish()
        self.assertFalse(r.success, r.message)
        util.wait_for(lambda: self.result.msg is not None, "~result")
        res = self.result.msg
        self.assertFalse(res.accepted)
        self.assertFalse(res.written)
        self.assertEqual(list(res.files_written), [])
        self.assertEqual(list(res.axes), ["x", "y", "z"])
        failed = [g.name for g in res.gates if not g.passed]
        self.assertIn("axis_z", failed)
        self.assertTrue(any("axis z: no wave sample was fed" in n for n in res.notes), res.notes)
        self.assertTrue(res.reason, "a refusal says why")
        self.assertEqual(res.report_file, os.path.join(self.work, "triad.report.yaml"))
        report = util.load_yaml(res.report_file)
        self.assertFalse(report["accepted"])
        for name in ("triad.yaml", "x.yaml", "y.yaml", "z.yaml"):
            self.assertFalse(os.path.exists(os.path.join(self.work, name + ".bak")), name)
        util.wait_for(lambda: self.status and self.status[2].get("run") == "idle", "the idle diagnostic")

        # Idle now: a new run starts, and aborts without writing.
        self.assertTrue(start("triad").success)
        abort = rospy.ServiceProxy("/calibrator/abort", Trigger)
        r = abort()
        self.assertTrue(r.success, r.message)
        self.assertIn("nothing written", r.message)


if __name__ == "__main__":
    rospy.init_node("triad_calibrator_inputs_test")
    rostest.rosrun("hrg_gyro", "triad_calibrator_inputs", TriadInputs)
