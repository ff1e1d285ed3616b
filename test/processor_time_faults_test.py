#!/usr/bin/env python3
"""Time faults on the live processor (sim time driven by this test): zero, duplicate and
out-of-order stamps are dropped and counted; a single sample stamped 1000 s ahead or 100 s back (a
clock glitch, a stray message) is dropped and counted and costs nothing else; a forward gap is not
integrated across (FLAG_GAP, dalpha 0) once ~jump_persist samples lie past it; a /clock jump back
resets the state (FLAG_RESET, alpha restarts) once ~jump_persist samples lie past it; processing
carries on after each fault, no output is NaN, and the input diagnostic counts every case; with
/clock stopped the diagnostics go on and report the input as stalled."""
import math
import os
import sys
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rosgraph_msgs.msg import Clock

from hrg_gyro.msg import ChannelAmplitudes, GyroOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402
from processor_reload_test import channels  # noqa: E402

DT = 0.005
RATE = 0.02  # rad/s of electrical angle: slow, well inside ~max_rate


class TimeFaults(unittest.TestCase):
    def setUp(self):
        self.outputs = []
        self.input_status = None
        self.input_summary = None
        rospy.Subscriber("/output", GyroOutput, self.outputs.append, queue_size=10000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag)
        self.clock = rospy.Publisher("/clock", Clock, queue_size=1000)
        self.pub = rospy.Publisher("/channels", ChannelAmplitudes, queue_size=1000)
        util.wait_for(lambda: self.pub.get_num_connections() > 0 and self.clock.get_num_connections() > 0,
                      "the processor to subscribe")
        self.seq = 0
        self.t = 100.0
        self.theta = 0.1

    def on_diag(self, msg):
        for s in msg.status:
            if s.name.endswith(": input"):
                self.input_status = dict((kv.key, kv.value) for kv in s.values)
                self.input_summary = (s.level, s.message, time.time())

    def tick(self, t):
        self.clock.publish(Clock(clock=rospy.Time.from_sec(t)))

    def send(self, stamp):
        self.seq += 1
        self.tick(max(stamp, self.t))
        self.pub.publish(channels(self.seq, stamp, self.theta))
        time.sleep(0.002)

    def stray(self, stamp):
        """One extra message with a glitched stamp; /clock stays where it is."""
        self.seq += 1
        self.tick(self.t)
        self.pub.publish(channels(self.seq, stamp, self.theta))
        time.sleep(0.002)

    def good(self, n):
        for _ in range(n):
            self.t += DT
            self.theta += RATE * DT
            self.send(self.t)

    def test_faults_are_dropped_counted_and_survived(self):
        persist = 5                         # ~jump_persist: the first 4 samples past a real jump are dropped
        self.good(40)                       # 39 outputs
        self.send(0.0)                      # zero stamp
        self.send(self.t)                   # duplicate
        self.send(self.t - 0.002)           # out of order (within ~backward_reset)
        self.good(20)                       # 20 outputs, the first reports 3 rejected before it
        self.stray(self.t + 1000.0)         # one sample 1000 s ahead: dropped
        self.good(20)                       # 20 outputs, the first reports 1 rejected, no flag
        self.stray(self.t - 100.0)          # one sample 100 s back: dropped
        self.good(20)                       # 20 outputs, the first reports 1 rejected, no flag
        self.t += 0.5                       # forward gap of 0.5 s > ~max_gap, for good
        self.good(20)                       # 4 dropped, then 16 outputs, the first flagged GAP with dalpha 0
        self.t -= 50.0                      # /clock and stamps jump back 50 s (a bag loop)
        self.good(20)                       # 4 dropped, the fifth re-anchors, 15 outputs, the first flagged RESET
        expected = 39 + 20 + 20 + 20 + (20 - persist + 1) + (20 - persist)
        util.wait_for(lambda: len(self.outputs) >= expected, "%d outputs" % expected)
        # Keep sim time moving so that the diagnostics publish the final counters.
        deadline = time.time() + 20
        while time.time() < deadline:
            self.good(20)
            s = self.input_status
            if s and s.get("resets (time went backwards)") == "1" and s.get("zero stamps") == "1":
                break
        out = self.outputs[:expected]

        for o in self.outputs:
            for v in (o.dalpha, o.alpha, o.rate, o.dt, o.scale_factor):
                self.assertTrue(math.isfinite(v), o)
        self.assertEqual(out[39].rejected_before, 3)
        for i in (59, 79):  # after each stray: that sample only
            self.assertEqual(out[i].rejected_before, 1, i)
            self.assertEqual(out[i].flags, 0, i)
            self.assertLess(abs(out[i].dt - DT), 1e-6, i)
        gap = 99
        gaps = [i for i, o in enumerate(out) if o.flags & GyroOutput.FLAG_GAP]
        self.assertEqual(gaps, [gap])
        self.assertEqual(out[gap].rejected_before, persist - 1)
        self.assertEqual(out[gap].dalpha, 0.0)
        self.assertAlmostEqual(out[gap].dt, 0.5 + persist * DT, places=6)
        self.assertEqual(out[gap].alpha, out[gap - 1].alpha)  # nothing integrated across the gap
        reset = gap + 20 - persist + 1
        resets = [i for i, o in enumerate(self.outputs) if o.flags & GyroOutput.FLAG_RESET]
        self.assertEqual(resets, [reset])
        # After the reset alpha restarts: the first output holds one increment only.
        self.assertEqual(out[reset].alpha, out[reset].dalpha)
        self.assertLess(abs(out[reset].dt - DT), 1e-6)
        # Between faults the angle follows the input: dtheta / K per step.
        k0 = -0.56
        for i in (10, 45, 70, 90, 110, 125):
            self.assertAlmostEqual(out[i].dalpha, RATE * DT / k0, delta=1e-6)

        s = self.input_status
        self.assertIsNotNone(s, "no input diagnostic")
        self.assertEqual(s["zero stamps"], "1")
        self.assertEqual(s["duplicate stamps"], "1")
        self.assertEqual(s["out-of-order stamps"], "1")
        self.assertEqual(s["stamp jumps dropped"], str(2 + 2 * (persist - 1)))
        self.assertEqual(s["gaps not integrated"], "1")
        self.assertEqual(s["resets (time went backwards)"], "1")
        self.assertAlmostEqual(float(s["largest gap (s)"]), 0.5 + persist * DT, places=6)

    def test_stopped_clock_is_reported_as_stalled(self):
        # A paused player stops /clock and the input together: diagnostics go on (on the wall
        # clock) and say that the input stalled once ~stall_timeout (5 s) of wall time has passed.
        self.good(100)
        stop = time.time()
        deadline = stop + 15.0

        def stalled():
            s = self.input_summary
            return s if s and s[2] > stop + 5.0 and "stalled" in s[1] else None
        level, message, when = util.wait_wall(stalled, deadline - time.time(), "'input stalled' with /clock stopped")
        self.assertEqual(level, DiagnosticStatus.ERROR, message)
        self.assertLess(when - stop, 8.0, "reported within ~stall_timeout plus two diagnostic periods")


if __name__ == "__main__":
    rospy.init_node("processor_time_faults_test")
    rostest.rosrun("hrg_gyro", "processor_time_faults", TimeFaults)
