#!/usr/bin/env python3
"""Diagnostics of the processor: OK on good input, ERROR naming the cause when every sample is bad
(NaN, degenerate wave, amplitudes out of range), WARN when some are or while messages are lost
(sequence gaps), ERROR when the input stalls, OK again on recovery;
the output never carries a NaN; the model status warns while the model is uncalibrated; the Imu
z variance is never 0, from the very first message of a fresh processor."""
import math
import os
import subprocess
import sys
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_srvs.srv import Trigger

from sensor_msgs.msg import Imu

from hrg_gyro.msg import ChannelAmplitudes, GyroOutput
from hrg_gyro.srv import StartCalibration

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
        util.wait_for(lambda: self.pub.get_num_connections() > 0, "the processor to subscribe")
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

    def feed(self, seconds, mutate=None, lose_every=0):
        """Publishes good channels for `seconds` (changed by `mutate`); with lose_every = n, two
        sequence numbers are skipped after every n-th message, as if two messages had been lost."""
        end = time.time() + seconds
        n = 0
        while time.time() < end:
            self.seq += 1
            self.t += 0.005
            m = channels(self.seq, self.t, 0.2 - 0.028 * (self.t % 100))
            if mutate:
                mutate(m)
            self.pub.publish(m)
            n += 1
            if lose_every and n % lose_every == 0:
                self.pub.impl.seq += 2  # rospy numbers the headers itself: skip two numbers there
            time.sleep(0.005)

    def status_after(self, name, since):
        def fresh():
            s = self.statuses.get(name)
            return s if s and s[2] > since else None
        return util.wait_for(fresh, "a diagnostic '%s'" % name)

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
        # The first good samples after the bad ones may be rejected (theta jumped); a busy host works
        # them off late, and a report can still count them: good samples keep coming until a report
        # covers them only (within 20 more s of feeding).
        level, message = self.status_after("wave", start + 1.5)[:2]
        for _ in range(10):
            if level == DiagnosticStatus.OK:
                break
            start = rospy.get_time()
            self.feed(2.0)
            level, message = self.status_after("wave", start + 1.5)[:2]
        self.assertEqual(level, DiagnosticStatus.OK, message)
        level, message = self.status_after("input", start + 1.5)[:2]
        self.assertNotEqual(level, DiagnosticStatus.ERROR, message)
        self.assertEqual(self.nan_outputs, 0)

    def test_huge_amplitudes_and_lost_messages_are_named(self):
        self.feed(2.0)

        def huge(m):  # finite, but the wave's energy overflows a double
            m.c_in, m.c_quad, m.s_in, m.s_quad = (v * 1e300 for v in (m.c_in, m.c_quad, m.s_in, m.s_quad))
        start = rospy.get_time()
        self.feed(2.5, huge)
        level, message = self.status_after("wave", start + 1.2)[:2]
        self.assertEqual(level, DiagnosticStatus.ERROR, message)
        self.assertIn("amplitude out of range", message)
        self.assertNotIn("non-finite", message)

        self.feed(1.5)
        lost_before = int(self.status_after("input", rospy.get_time())[3]["lost (sequence gaps)"])
        start = rospy.get_time()
        self.feed(2.5, lose_every=20)
        level, message, _, values = self.status_after("input", start + 1.2)
        self.assertEqual(level, DiagnosticStatus.WARN, message)
        self.assertIn("lost (sequence gaps)", message)
        self.assertGreater(int(values["lost (sequence gaps)"]), lost_before)
        start = rospy.get_time()
        self.feed(2.5)  # no new loss: the warning clears
        level, message = self.status_after("input", start + 1.5)[:2]
        self.assertEqual(level, DiagnosticStatus.OK, message)

    def test_calibrator_refuses_start_while_a_run_is_in_progress(self):
        util.wait_for_service("/cal/calibrator/start")
        start = rospy.ServiceProxy("/cal/calibrator/start", StartCalibration)
        abort = rospy.ServiceProxy("/cal/calibrator/abort", Trigger)
        r = start(method="")  # the autostarted run is in progress
        self.assertFalse(r.success, r.message)
        self.assertIn("a run is in progress", r.message)
        self.assertIn("~finish or ~abort it first", r.message)
        self.assertTrue(abort().success)
        r = start(method="step")
        self.assertTrue(r.success, r.message)
        r = start(method="dual_rate")
        self.assertFalse(r.success, "a second ~start must not discard the step run: " + r.message)
        self.assertIn("(step)", r.message)
        self.assertTrue(abort().success)

    def test_a_nodelet_that_fails_to_start_logs_why(self):
        # A manager of the test's own, whose log (stderr) is read back; a processor nodelet with a
        # missing model is loaded into it.
        log_path = os.path.join("/tmp", "hrg_gyro_test_manager_%d.log" % os.getpid())
        missing = "/nonexistent/hrg_gyro_params.yaml"
        rospy.set_param("/broken_processor/parameter_file", missing)
        with open(log_path, "w") as log:
            manager = subprocess.Popen(["rosrun", "nodelet", "nodelet", "manager", "__name:=test_manager"],
                                       stdout=log, stderr=subprocess.STDOUT)
        try:
            util.wait_for_service("/test_manager/load_nodelet")
            load = subprocess.run(["rosrun", "nodelet", "nodelet", "load", "hrg_gyro/Processor", "/test_manager",
                                   "__name:=broken_processor", "--no-bond"], stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)
            self.assertNotEqual(load.returncode, 0, load.stdout)

            def fatal_line():
                with open(log_path) as f:
                    return [l for l in f if "FATAL" in l and "broken_processor failed to start" in l]
            lines = util.wait_for(fatal_line, "the manager to log why the nodelet failed")
            self.assertIn(missing, lines[0], "the reason is in the log")
        finally:
            manager.terminate()
            manager.wait(timeout=20)
            os.remove(log_path)

    def test_imu_variance_never_zero_and_uncalibrated_model_warns(self):
        # A processor of its own (namespace fresh), so that its very first outputs are seen.
        imu = util.Latest("/fresh/imu/data_raw", Imu, keep_all=True)
        pub = rospy.Publisher("/fresh/channels", ChannelAmplitudes, queue_size=1000)
        util.wait_for(lambda: pub.get_num_connections() > 0 and imu.sub.get_num_connections() > 0,
                      "the fresh processor")
        t = time.time()
        for seq in range(1, 401):
            t += 0.005
            pub.publish(channels(seq, t, 0.2 - 0.028 * (t % 100)))
            time.sleep(0.004)
        util.wait_for(lambda: imu.count >= 390, "the fresh processor's Imu messages")
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
