#!/usr/bin/env python3
"""driver_sim plays a triad scenario (test/scenarios/triad_short.yaml) live, as a node and as a
nodelet: in its namespace it publishes <axis>/channels and <axis>/truth for x, y and z (frame_id the
axis), turntable/state, fixture/position and the body's truth (frame_id the triad's imu_link), the
three axes at the same stamps, each axis's truth rate its row of A times the body's rate."""
import os
import sys
import unittest

import rospy
import rostest

from hrg_gyro.msg import BodyTruth, ChannelAmplitudes, FixturePosition, GroundTruth, TurntableState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

AXES = ("x", "y", "z")
# Rows of A in test/scenarios/triad_short.yaml: [A_xy, A_xz], [A_yx, A_yz], [A_zx, A_zy].
A = ((1.0, 1.2e-4, -0.8e-4), (0.5e-4, 1.0, 2.1e-4), (-1.6e-4, 0.9e-4, 1.0))


class TriadDriverSim(unittest.TestCase):
    def check(self, ns):
        channels = {a: util.Latest("/%s/%s/channels" % (ns, a), ChannelAmplitudes, keep_all=True) for a in AXES}
        truth = {a: util.Latest("/%s/%s/truth" % (ns, a), GroundTruth, keep_all=True) for a in AXES}
        table = util.Latest("/%s/turntable/state" % ns, TurntableState, keep_all=True)
        fixture = util.Latest("/%s/fixture/position" % ns, FixturePosition, keep_all=True)
        body = util.Latest("/%s/truth" % ns, BodyTruth, keep_all=True)
        util.wait_for(lambda: fixture.count >= 3 and all(c.count > 400 for c in channels.values()) and
                      body.count > 400 and all(t.count > 400 for t in truth.values()), ns + " triad topics")
        for s in list(channels.values()) + list(truth.values()) + [table, fixture, body]:
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

    def test_node(self):
        self.check("triad_node")

    def test_nodelet(self):
        self.check("triad_nodelet")


if __name__ == "__main__":
    rospy.init_node("triad_driver_sim_test")
    rostest.rosrun("hrg_gyro", "triad_driver_sim", TriadDriverSim)
