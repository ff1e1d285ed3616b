#!/usr/bin/env python3
"""Who turns the wave (test/precession_source.test).

driver_sim runs a still gyro with a precession loop; two processors read it, a nodelet in the driver's
manager and a standalone node with remapped inputs. This node, no calibrator, commands the loop to
turn the wave at 0.5 rad/s and then stops it. The wave's turning reads as about 0.9 rad/s of body
rate; both processors must flag exactly the outputs over which the loop turned the wave, and only
those (FLAG_PRECESSING, their Imu z variance 1e6), and their `precession` diagnostic must be WARN
naming the rate and this node while the rate is in force, and OK again once it is not. The verdicts
are taken on the simulated stamps, whatever the pace."""
import os
import sys
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import Imu

from hrg_gyro.msg import GroundTruth, GyroOutput, PrecessionCommand, PrecessionState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

RATE = 0.5  # rad/s, electrical: the stranger's command
FLAG_PRECESSING = GyroOutput.FLAG_PRECESSING
PERIOD = 5000000  # ns between samples (200 Hz)
PROCESSORS = ("field", "standalone")


class Statuses(object):
    """The `precession` status of each processor, every report kept."""

    def __init__(self):
        self.reports = {ns: [] for ns in PROCESSORS}
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self._on, queue_size=100)

    def _on(self, msg):
        for s in msg.status:
            if not s.name.endswith(": precession"):
                continue
            for ns in PROCESSORS:
                if s.name.startswith("/%s/processor" % ns) or s.name.startswith("%s/processor" % ns):
                    self.reports[ns].append((s.level, s.message, dict((kv.key, kv.value) for kv in s.values)))

    def seen(self, ns, level, text, after=0):
        return any(lv == level and text in m for lv, m, _ in self.reports[ns][after:])


class PrecessionSource(unittest.TestCase):
    def test_a_strangers_command_is_flagged_and_named(self):
        me = rospy.get_name()
        truth = util.Latest("/field/truth", GroundTruth)
        states = util.Latest("/field/precession/state", PrecessionState, keep_all=True)
        outputs = {ns: util.Latest("/%s/output" % ns, GyroOutput, keep_all=True) for ns in PROCESSORS}
        imus = {ns: util.Latest("/%s/imu/data_raw" % ns, Imu, keep_all=True) for ns in PROCESSORS}
        statuses = Statuses()
        pub = rospy.Publisher("/field/command/precession", PrecessionCommand, queue_size=10)
        util.wait_for(lambda: truth.count > 0 and states.count > 200 and pub.get_num_connections() >= 1 and
                      all(o.count > 200 for o in outputs.values()), "the driver's state, both processors' outputs and the driver listening to commands")
        self.assertEqual(states.msg.rate, 0.0)
        for ns in PROCESSORS:
            util.wait_for(lambda: statuses.seen(ns, DiagnosticStatus.OK, "not turned on command"), "%s: precession OK before any command" % ns)

        def command(rate, since):
            """Commands `rate`; returns the stamp of the first state record (after `since`) that has it."""
            msg = PrecessionCommand()
            msg.header.stamp = rospy.Time.now()
            msg.rate = rate
            pub.publish(msg)
            util.wait_for(lambda: states.msg.rate == rate, "precession/state at %g rad/s" % rate)
            return min(m.header.stamp.to_nsec() for m in list(states.all)
                       if m.rate == rate and m.header.stamp.to_nsec() > since)

        seen_before = {ns: len(statuses.reports[ns]) for ns in PROCESSORS}
        on = command(RATE, 0)
        self.assertEqual(states.msg.source, me, "the driver names the node that commanded the rate in force")
        # The WARN names the rate and this node; the rate stays on until both processors have said so.
        for ns in PROCESSORS:
            util.wait_for(lambda: statuses.seen(ns, DiagnosticStatus.WARN,
                                                "%g rad/s in force, commanded by %s" % (RATE, me), seen_before[ns]), "%s: precession WARN naming %s" % (ns, me))
        util.wait_for(lambda: states.msg.header.stamp.to_nsec() > on + 2000000000, "2 s of the wave turning")
        seen_on = {ns: len(statuses.reports[ns]) for ns in PROCESSORS}
        off = command(0.0, on)
        # 2 s of simulated time after the stop, out of every processor.
        end = off + 2000000000
        util.wait_for(lambda: all(o.msg.header.stamp.to_nsec() > end for o in outputs.values()), "2 s of outputs after the stop")
        for ns in PROCESSORS:
            util.wait_for(lambda: statuses.seen(ns, DiagnosticStatus.OK, "not turned on command", seen_on[ns]), "%s: precession OK again after the stop" % ns)

        # The switches as the state records show them: this node's copy must hold the records just
        # before each (200 Hz, consecutive stamps), else `on` and `off` would not be the switches.
        by_stamp = {m.header.stamp.to_nsec(): m for m in states.all}
        self.assertEqual(by_stamp[on - PERIOD].rate, 0.0)
        self.assertEqual(by_stamp[off - PERIOD].rate, RATE)
        for ns in PROCESSORS:
            flagged = unflagged = 0
            imu_variance = {m.header.stamp.to_nsec(): m.angular_velocity_covariance[8] for m in imus[ns].all}
            for o in outputs[ns].all:
                t = o.header.stamp.to_nsec()
                if t > end:
                    continue
                precessing = bool(o.flags & FLAG_PRECESSING)
                if on <= t <= off:
                    # The rate in force at either end of (t - 5 ms, t]: flagged, and it reads as body rate.
                    self.assertTrue(precessing, "%s: output at %d not flagged" % (ns, t))
                    if on + PERIOD <= t <= off - PERIOD:  # whole intervals at the rate (switches mid-sample)
                        self.assertGreater(abs(o.rate), RATE, "%s: the wave's turning reads as body rate" % ns)
                    self.assertEqual(imu_variance.get(t, 1e6), 1e6, "%s: the Imu at %d" % (ns, t))
                    flagged += 1
                elif t <= on - PERIOD or t >= off + 2 * PERIOD:
                    # Rate 0 at both ends and the commanded angle still (the output after the stop's
                    # sample may see the angle move, if the stop came after that sample's centre).
                    self.assertFalse(precessing, "%s: output at %d flagged" % (ns, t))
                    self.assertLess(abs(o.rate), 0.05, "%s: a still gyro" % ns)
                    self.assertLess(imu_variance.get(t, 0.0), 1.0, "%s: the Imu at %d" % (ns, t))
                    unflagged += 1
            rospy.loginfo("%s: %d outputs flagged PRECESSING over %.3f s of commanded rotation, %d not", ns, flagged,
                          (off - on) * 1e-9, unflagged)
            # Each output this node received is checked above; nearly all of them came (rospy may drop
            # a few under load, the processors drop none).
            self.assertGreater(flagged, 0.9 * ((off - on) // PERIOD + 1), ns)
            self.assertGreater(unflagged, 400, ns)
            _, _, values = [r for r in statuses.reports[ns] if r[0] == DiagnosticStatus.WARN][-1]
            self.assertEqual(values["commanded by"], me)


if __name__ == "__main__":
    rospy.init_node("precession_source_test")
    rostest.rosrun("hrg_gyro", "precession_source", PrecessionSource)
