#!/usr/bin/env python3
"""driver_sim plays a triad scenario (test/scenarios/triad_short.yaml) live, as a node and as a
nodelet: in its namespace it publishes <axis>/channels and <axis>/truth for x, y and z (frame_id the
axis), turntable/state, fixture/position and the body's truth (frame_id the triad's imu_link), the
three axes at the same stamps, each axis's truth rate its row of A times the body's rate; and the
accelerometer the launch file adds to the scenario, accel/data_raw: gravity through the true body
orientation and the mounting, plus the bias, with its noise's covariance. On
config/scenarios/north_sweep.yaml (each axis run by the averaged resonator on its schedule) each axis
also publishes <axis>/precession/state with each of its channel samples: the schedule's rate in force,
the commanded angle, source "schedule"."""
import math
import os
import sys
import unittest

import rospy
import rostest

from sensor_msgs.msg import Imu

from hrg_gyro.msg import BodyTruth, ChannelAmplitudes, FixturePosition, GroundTruth, PrecessionState, TurntableState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

AXES = ("x", "y", "z")
# Rows of A in test/scenarios/triad_short.yaml: [A_xy, A_xz], [A_yx, A_yz], [A_zx, A_zy].
A = ((1.0, 1.2e-4, -0.8e-4), (0.5e-4, 1.0, 2.1e-4), (-1.6e-4, 0.9e-4, 1.0))
# The accelerometer of test/triad_driver_sim.test.
ACCEL_BIAS = (0.01, -0.02, 0.03)
ACCEL_NOISE = 1.0e-3
ACCEL_MOUNTING = (0.1, -0.2, 0.3)  # roll, pitch, yaw
G = 9.80665


def rotation_rpy(roll, pitch, yaw):
    """Rz(yaw) Ry(pitch) Rx(roll), rows."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw),
                              math.sin(yaw))
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def up_in_body(q):
    """The third row of the rotation of quaternion q (body -> table): the table's up in the body."""
    x, y, z, w = q.x, q.y, q.z, q.w
    return (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y))


class TriadDriverSim(unittest.TestCase):
    def check(self, ns):
        channels = {a: util.Latest("/%s/%s/channels" % (ns, a), ChannelAmplitudes, keep_all=True) for a in AXES}
        truth = {a: util.Latest("/%s/%s/truth" % (ns, a), GroundTruth, keep_all=True) for a in AXES}
        table = util.Latest("/%s/turntable/state" % ns, TurntableState, keep_all=True)
        fixture = util.Latest("/%s/fixture/position" % ns, FixturePosition, keep_all=True)
        body = util.Latest("/%s/truth" % ns, BodyTruth, keep_all=True)
        accel = util.Latest("/%s/accel/data_raw" % ns, Imu, keep_all=True)
        util.wait_for(lambda: fixture.count >= 3 and all(c.count > 400 for c in channels.values()) and
                      body.count > 400 and all(t.count > 400 for t in truth.values()) and accel.count > 400,
                      ns + " triad topics")
        for s in list(channels.values()) + list(truth.values()) + [table, fixture, body, accel]:
            s.sub.unregister()
        for a in AXES:
            self.assertEqual({m.header.frame_id for m in channels[a].all}, {a})
            self.assertEqual({m.header.frame_id for m in truth[a].all}, {a})
        self.assertEqual({m.header.frame_id for m in fixture.all + body.all + table.all}, {"imu_link"})
        # Shared stamps: every stamp of x's channels that all three received is one sample of each.
        stamps = [set(m.header.stamp for m in channels[a].all) for a in AXES]
        common = stamps[0] & stamps[1] & stamps[2]
        self.assertGreater(len(common), 300)
        self.assertGreater(len(common), 0.9 * min(len(s) for s in stamps))
        # Each axis's truth rate is its row of A times the body's rate of the same stamp.
        rates = {m.header.stamp: m.angular_velocity for m in body.all}
        checked = 0
        for i, a in enumerate(AXES):
            for m in truth[a].all:
                w = rates.get(m.header.stamp)
                if w is None:
                    continue
                expected = A[i][0] * w.x + A[i][1] * w.y + A[i][2] * w.z
                self.assertAlmostEqual(m.inertial_rate, expected, delta=1e-15)
                checked += 1
        self.assertGreater(checked, 900)
        # The session starts clamped in its first position, z up.
        first = fixture.all[0]
        self.assertEqual((first.index, first.name, first.locked), (0, "z up", True))
        self.assertAlmostEqual(first.body_to_table.w, 1.0, delta=1e-15)
        self.assertGreater(table.count, 300)
        self.check_accelerometer(accel.all, body.all)

    def check_accelerometer(self, accel, body):
        self.assertEqual({m.header.frame_id for m in accel}, {"accel_link"})
        variance = ACCEL_NOISE ** 2
        for m in accel:
            self.assertEqual(m.orientation_covariance[0], -1.0)
            self.assertEqual(m.angular_velocity_covariance[0], -1.0)
            self.assertEqual(list(m.linear_acceleration_covariance), [variance, 0, 0, 0, variance, 0, 0, 0, variance])
        # The table's axis is up: the specific force is g along the table's up, seen in the body through
        # the true body_to_table, then in the accelerometer's frame through the mounting, plus the bias.
        mounting = rotation_rpy(*ACCEL_MOUNTING)
        up = {m.header.stamp: up_in_body(m.body_to_table) for m in body}
        errors = []
        for m in accel:
            u = up.get(m.header.stamp)
            if u is None:
                continue
            f = (m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z)
            for j in range(3):
                expected = G * sum(mounting[k][j] * u[k] for k in range(3)) + ACCEL_BIAS[j]
                errors.append(f[j] - expected)
        self.assertGreater(len(errors), 900)
        # White noise of 1e-3 m/s^2: its rms within 10 %, nothing beyond 6 sigma, mean near 0.
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        self.assertAlmostEqual(rms / ACCEL_NOISE, 1.0, delta=0.1)
        self.assertLess(max(abs(e) for e in errors), 6 * ACCEL_NOISE)
        self.assertLess(abs(sum(errors) / len(errors)), 5 * ACCEL_NOISE / math.sqrt(len(errors)))

    def test_node(self):
        self.check("triad_node")

    def test_axes_that_precess_publish_their_precession_state(self):
        # north_sweep.yaml: rest (its first command, rate 0) until 5 s, then +0.2 rad/s (electrical).
        channels = {a: util.Latest("/triad_sweep/%s/channels" % a, ChannelAmplitudes, keep_all=True) for a in AXES}
        states = {a: util.Latest("/triad_sweep/%s/precession/state" % a, PrecessionState, keep_all=True)
                  for a in AXES}
        util.wait_for(lambda: all(any(m.rate != 0.0 for m in s.all) and s.count > 1200 for s in states.values()),
                      "each axis's precession state past the first command")
        for s in list(channels.values()) + list(states.values()):
            s.sub.unregister()
        for a in AXES:
            received = states[a].all
            self.assertEqual({m.header.frame_id for m in received}, {a})
            self.assertEqual({m.source for m in received}, {"schedule"})
            # One state with each channel sample, at its stamp.
            stamps = set(m.header.stamp for m in channels[a].all)
            self.assertGreater(len(stamps & set(m.header.stamp for m in received)), 0.9 * len(received))
            # Live, the stamps start at the wall clock: the angle dates the second command instead.
            resting = [m for m in received if m.rate == 0.0]
            turning = [m for m in received if m.rate != 0.0]
            self.assertEqual({(m.angle, m.commands) for m in resting}, {(0.0, 1)})
            self.assertEqual({(m.rate, m.commands) for m in turning}, {(0.2, 2)})
            switch = [m.header.stamp.to_sec() - m.angle / 0.2 for m in turning]
            self.assertLess(max(switch) - min(switch), 1e-6)  # one start: the angle grows at 0.2 rad/s
            if resting:
                self.assertLess(resting[-1].header.stamp.to_sec(), min(switch))
                self.assertLess(min(switch), turning[0].header.stamp.to_sec())

    def test_nodelet(self):
        self.check("triad_nodelet")


if __name__ == "__main__":
    rospy.init_node("triad_driver_sim_test")
    rostest.rosrun("hrg_gyro", "triad_driver_sim", TriadDriverSim)
