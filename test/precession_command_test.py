#!/usr/bin/env python3
"""The command path of a field calibration (test/precession_command.test).

driver_sim on the averaged resonator (test/scenarios/precession_short.yaml) takes the virtual rates
this node commands on /field/command/precession: precession/state reports each rate in force and its
integral, and the true wave angle turns at the commanded rate times the drive's realised gain (plus
the Earth rate's and the bias's share), either way; a recorder keeps the commands in a bag. driver_sim
on a gyro without the loop (/plain) warns that it ignores a command and goes on publishing."""
import math
import os
import sys
import unittest

import rosbag
import rospy
import rostest
from rosgraph_msgs.msg import Log

from hrg_gyro.msg import ChannelAmplitudes, GroundTruth, PrecessionCommand, PrecessionState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

W = 0.5  # rad/s, electrical
# The scenario's drive: the precession channel 3e-3 off, the forcers' mean gain error 0.5e-3, so
# G_v = 1.0035 over a full turn (first order; the exact settled gain differs by 1e-8). The wave also
# turns at K0 Omega_E (K0 = -0.56 at 0.9 rad of latitude) plus the bias of 1e-5 rad/s.
GAIN = 1.0 + 3e-3 + 0.5 * (2e-3 - 1e-3)
STILL_RATE = -0.56 * 7.292115e-5 * math.sin(0.9) + 1e-5


def full_turn_rate(samples, t0):
    """Mean rate of the true angle over its first full turn (2 pi) after t0: 2 pi over the time it
    took, which over a whole turn leaves out the gain's and the drift's harmonics to second order."""
    points = [(t, th) for t, th in samples if t >= t0]
    start_t, start_theta = points[0]
    for (ta, a), (tb, b) in zip(points, points[1:]):
        if abs(b - start_theta) >= 2 * math.pi:
            target = start_theta + math.copysign(2 * math.pi, b - start_theta)
            t_end = ta + (tb - ta) * (target - a) / (b - a)
            return math.copysign(2 * math.pi, b - start_theta) / (t_end - start_t)
    raise AssertionError("the wave did not turn by 2 pi after %.1f s (%d samples)" % (t0, len(points)))


class PrecessionCommandTest(unittest.TestCase):
    def test_commands_are_executed_reported_and_recorded(self):
        truth = util.Latest("/field/truth", GroundTruth, keep_all=True)
        state = util.Latest("/field/precession/state", PrecessionState, keep_all=True)
        commands = util.Latest("/field/command/precession", PrecessionCommand, keep_all=True)
        pub = rospy.Publisher("/field/command/precession", PrecessionCommand, queue_size=10, latch=False)
        # Three subscribers of the commands: the driver, the recorder and this test's own `commands`
        # (rospy connects a node's publisher to its own subscriber). Waiting for two let the first
        # command go out before a recorder that started late under load: it then never saw its
        # three messages and never closed its bag.
        util.wait_for(lambda: truth.count > 100 and state.count > 100 and pub.get_num_connections() >= 3,
                      "the driver's truth, its precession state, and the driver, the recorder and this test "
                      "subscribed to the commands")
        self.assertEqual(state.msg.rate, 0.0)
        self.assertEqual(state.msg.commands, 0)
        # The recorder writes <bag>.active and renames it when it closes: a bag of an earlier run must go.
        path = rospy.get_param("~bag")
        if os.path.exists(path):
            os.remove(path)
        segments = []
        for rate in (W, -W, 0.0):
            msg = PrecessionCommand()
            msg.header.stamp = rospy.Time.now()
            msg.rate = rate
            pub.publish(msg)
            util.wait_for(lambda: state.msg.rate == rate, "precession/state at %g rad/s" % rate)
            since = state.msg.header.stamp.to_sec()
            if rate != 0.0:
                # A full turn of theta at 0.5 rad/s is 12.6 s; the loops take well under a second.
                util.wait_for(lambda: truth.msg.header.stamp.to_sec() > since + 15.0, "15 s of the wave")
            segments.append((rate, since))
        for s in (truth, state, commands):
            s.sub.unregister()
        samples = [(m.header.stamp.to_sec(), m.theta) for m in truth.all]
        for rate, since in segments[:2]:
            measured = full_turn_rate(samples, since + 1.0)
            expected = GAIN * rate + STILL_RATE
            rospy.loginfo("commanded %g rad/s: the wave turned at %.7f rad/s, expected %.7f", rate, measured,
                          expected)
            self.assertAlmostEqual(measured, expected, delta=5e-6)
            self.assertGreater(abs(measured - (rate + STILL_RATE)), 1e-3)  # the gain is the drive's, not 1
        # The commanded angle is the integral of the rate in force: exactly the rate between samples.
        plus = [m for m in state.all if m.rate == W]
        self.assertGreater(len(plus), 100)
        slope = (plus[-1].angle - plus[0].angle) / (plus[-1].header.stamp - plus[0].header.stamp).to_sec()
        self.assertAlmostEqual(slope, W, delta=1e-9)
        self.assertEqual(state.all[-1].commands, 3)
        self.assertEqual([m.rate for m in commands.all], [W, -W, 0.0])

        # The recorder stopped after the three commands and closed its bag.
        util.wait_for(lambda: os.path.exists(path), "the recorded bag " + path)
        with rosbag.Bag(path) as bag:
            recorded = [m.rate for _, m, _ in bag.read_messages(topics=["/field/command/precession"])]
        self.assertEqual(recorded, [W, -W, 0.0])

    def test_a_gyro_without_the_loop_warns_and_goes_on(self):
        warnings = util.Latest("/rosout", Log, keep_all=True)
        channels = util.Latest("/plain/channels", ChannelAmplitudes)
        pub = rospy.Publisher("/plain/command/precession", PrecessionCommand, queue_size=10)
        util.wait_for(lambda: channels.count > 10 and pub.get_num_connections() >= 1, "the plain driver")
        msg = PrecessionCommand()
        msg.rate = W
        pub.publish(msg)
        util.wait_for(lambda: any("no precession loop" in m.msg and m.level == Log.WARN for m in warnings.all),
                      "driver_sim's warning")
        before = channels.count
        util.wait_for(lambda: channels.count > before + 10, "channels after the command")
        self.assertEqual(rospy.get_published_topics().count(["/plain/precession/state", "hrg_gyro/PrecessionState"]),
                         0)


if __name__ == "__main__":
    rospy.init_node("precession_command_test")
    rostest.rosrun("hrg_gyro", "precession_command", PrecessionCommandTest)
