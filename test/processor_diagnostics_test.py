#!/usr/bin/env python3
"""Diagnostics of the processor: OK on good input, ERROR naming the cause when every sample is bad
(NaN, degenerate wave), WARN when some are, ERROR when the input stalls, OK again on recovery;
the output never carries a NaN; the model status warns while the model is uncalibrated; the Imu
z variance is never 0, from the very first message of a fresh processor."""
import math
import os
import sys
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from sensor_msgs.msg import Imu

from hrg_gyro.msg import ChannelAmplitudes, GyroOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402
from processor_reload_test import channels  # noqa: E402


class Diagnostics(unittest.TestCase):
    def setUp(self):
        self.statuses = {}
        self.nan_outputs = 0
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag)
        rospy.Subscriber("/output", GyroOutput, self.on_output)
        self.pub = rospy.Publisher("/channels", ChannelAmplitudes, queue_size=100)
        util.wait_for(lambda: self.pub.get_num_connections() > 0, 30, "the processor to subscribe")
        self.seq = 0
        self.t = time.time()

    def on_diag(self, msg):
        for s in msg.status:
            # the second processor's statuses (namespace fresh) are kept apart as "fresh/<name>"
            prefix = "fresh/" if "fresh" in s.name.split(": ")[0] else ""
            self.statuses[prefix + s.name.split(": ")[-1]] = (s.level, s.message, rospy.get_time(),
                                                              dict((kv.key, kv.value) for kv in s.values))

    def on_output(self, msg):
        if any(math.isnan(v) for v in (msg.dalpha, msg.alpha, msg.rate, msg.scale_factor)):
            self.nan_outputs += 1

    def feed(self, seconds, mutate=None):
        end = time.time() + seconds
        while time.time() < end:
            self.seq += 1
            self.t += 0.005
            m = channels(self.seq, self.t, 0.2 - 0.028 * (self.t % 100))
            if mutate:
                mutate(m)
            self.pub.publish(m)
            time.sleep(0.005)

    def status_after(self, name, since):
        def fresh():
            s = self.statuses.get(name)
            return s if s and s[2] > since else None
        return util.wait_for(fresh, 10, "a diagnostic '%s'" % name)

    def test_good_bad_stalled_recovered(self):
        self.feed(2.5)
        level, message = self.status_after("wave", rospy.get_time())[:2]
        self.assertEqual(level, DiagnosticStatus.OK, message)

        def nan(m):
            m.s_in = float("nan")
        start = rospy.get_time()
        self.feed(2.5, nan)
        level, message = self.status_after("wave", start + 1.2)[:2]
        self.assertEqual(level, DiagnosticStatus.ERROR, message)
        self.assertIn("non-finite", message)

        def degenerate(m):  # a travelling wave: A = B
            m.c_in, m.c_quad, m.s_in, m.s_quad = 1.0, 0.0, 0.0, 1.0
        start = rospy.get_time()
        self.feed(2.5, degenerate)
        level, message = self.status_after("wave", start + 1.2)[:2]
        self.assertEqual(level, DiagnosticStatus.ERROR, message)
        self.assertIn("degenerate", message)

        start = rospy.get_time()
        time.sleep(2.5)  # nothing arrives
        level, message = self.status_after("input", start + 1.0)[:2]
        self.assertEqual(level, DiagnosticStatus.ERROR, message)
        self.assertIn("stalled", message)

        start = rospy.get_time()
        self.feed(3.0)
        level, message = self.status_after("wave", start + 1.5)[:2]
        self.assertEqual(level, DiagnosticStatus.OK, message)
        level, message = self.status_after("input", start + 1.5)[:2]
        self.assertNotEqual(level, DiagnosticStatus.ERROR, message)
        self.assertEqual(self.nan_outputs, 0)

    def test_imu_variance_never_zero_and_uncalibrated_model_warns(self):
        # A processor of its own (namespace fresh), so that its very first outputs are seen.
        imu = util.Latest("/fresh/imu/data_raw", Imu, keep_all=True)
        pub = rospy.Publisher("/fresh/channels", ChannelAmplitudes, queue_size=1000)
        util.wait_for(lambda: pub.get_num_connections() > 0 and imu.sub.get_num_connections() > 0, 30,
                      "the fresh processor")
        t = time.time()
        for seq in range(1, 401):
            t += 0.005
            pub.publish(channels(seq, t, 0.2 - 0.028 * (t % 100)))
            time.sleep(0.004)
        util.wait_for(lambda: imu.count >= 390, 20, "the fresh processor's Imu messages")
        variances = [m.angular_velocity_covariance[8] for m in imu.all]
        self.assertTrue(all(v > 0.0 for v in variances), "a zero or negative variance: %s" % variances[:5])
        # The first ones carry the documented start-up value, later ones the measured noise (this
        # input is noiseless, so the documented floor).
        self.assertEqual(variances[0], 1e-4)
        self.assertEqual(variances[-1], 1e-12)
        start = rospy.get_time()
        for name in ("model", "fresh/model"):
            level, message = self.status_after(name, start)[:2]
            self.assertEqual(level, DiagnosticStatus.WARN, message)
            self.assertIn("uncalibrated", message)

    def test_memory_status(self):
        # The live heap is reported, and trimmed every ~heap_trim_period (1 s in this launch).
        self.feed(1.0)
        start = rospy.get_time()
        time.sleep(3.0)
        level, message, _, values = self.status_after("memory", start + 2.0)
        self.assertEqual(level, DiagnosticStatus.OK, message)
        heap = float(values["process heap in use (MiB)"])
        self.assertTrue(0.1 < heap < 1000.0, heap)
        self.assertGreaterEqual(int(values["heap trims"]), 2)


if __name__ == "__main__":
    rospy.init_node("processor_diagnostics_test")
    rostest.rosrun("hrg_gyro", "processor_diagnostics", Diagnostics)
