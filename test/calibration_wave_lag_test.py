#!/usr/bin/env python3
"""The calibrator's auto-finish does not depend on which of its streams comes first
(test/calibration_wave_lag.test). The rule needs both: the rest, from the table records, and the
data complete, from the waves. Live, the waves come a hop later (through the processor), and on a
busy host they lagged the table by more than the last rest's margin: the last table record then
found the data incomplete and no later record came to check again, so the run never finished.

Here the lag is forced: `hrg_bag simulate` writes a short constant-rate session and `hrg_bag process`
its waves; this node publishes every table record, with the waves 50 s of stamps behind them (no
result may come: the data are not complete without the end of the plateau), then the last waves.
The calibrator must then finish, accept and write."""
import os
import subprocess
import sys
import unittest

import rosbag
import rospy
import rostest

from hrg_gyro.msg import CalibrationResult, TurntableState, WaveState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

LAG = 50.0  # s of stamps the waves come behind the table (the plateau's coverage completes 38 s before the end)
HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()


def hrg_bag(*args):
    p = subprocess.run([HRG_BAG] + list(args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    if p.returncode != 0:
        raise AssertionError("hrg_bag %s: exit %d\n%s" % (" ".join(args), p.returncode, p.stdout[-3000:]))


def messages(bag_path, topic):
    with rosbag.Bag(bag_path) as bag:
        return [m for _, m, _ in bag.read_messages(topics=[topic])]


class WaveLag(unittest.TestCase):
    def test_finishes_when_the_waves_come_after_the_last_table_record(self):
        work = rospy.get_param("~work_dir")
        session, waves_bag = os.path.join(work, "session.bag"), os.path.join(work, "waves.bag")
        hrg_bag("simulate", "--scenario", rospy.get_param("~scenario"), "--out", session)
        hrg_bag("process", session, "--params", rospy.get_param("~prior"), "--out", waves_bag)
        table, waves = messages(session, "/turntable/state"), messages(waves_bag, "/wave")
        self.assertEqual(len(table), len(waves))

        results = util.Latest("/calibrator/result", CalibrationResult)
        calibrator = util.Diagnostic("calibrator: calibration", ("turntable states", "wave samples", "runs"))
        # Queues that hold the whole session: nothing is dropped however fast this node publishes.
        table_pub = rospy.Publisher("/turntable/state", TurntableState, queue_size=len(table))
        wave_pub = rospy.Publisher("/wave", WaveState, queue_size=len(waves))
        util.wait_for(lambda: table_pub.get_num_connections() > 0 and wave_pub.get_num_connections() > 0 and
                      results.sub.get_num_connections() > 0 and calibrator.get("turntable states") == "0",
                      "the calibrator's subscriptions and its running session")

        # The table first, the waves LAG s of stamps behind it (within the calibrator's 60 s pairing
        # window), up to the table's last record: the waves then lack the end of the plateau, whose
        # coverage completes the data, and the last table record finds them incomplete.
        cut = table[-1].header.stamp - rospy.Duration(LAG)
        early = [m for m in waves if m.header.stamp <= cut]
        queue = sorted([(m.header.stamp, 0, i) for i, m in enumerate(table)] +
                       [(m.header.stamp + rospy.Duration(LAG), 1, i) for i, m in enumerate(early)])
        for _, kind, i in queue:
            (table_pub if kind == 0 else wave_pub).publish(table[i] if kind == 0 else early[i])
        util.wait_for(lambda: calibrator.get("turntable states") == str(len(table)) and
                      calibrator.get("wave samples") == str(len(early)),
                      lambda: "%d table records and %d waves at the calibrator (diagnostic: %r)" %
                      (len(table), len(early), calibrator.values))
        self.assertIsNone(results.msg, "a result without the end of the plateau's waves")
        self.assertLess(float(calibrator.get("progress")), 1.0)

        for m in waves[len(early):]:
            wave_pub.publish(m)
        util.wait_for(lambda: results.msg is not None,
                      lambda: "a result once the last waves came (diagnostic: %s %r)" % (calibrator.message,
                                                                                        calibrator.values))
        r = results.msg
        self.assertEqual(r.method, "constant_rate")
        self.assertTrue(r.accepted, r.reason)
        self.assertTrue(r.written, r.reason)


if __name__ == "__main__":
    rospy.init_node("calibration_wave_lag_test")
    rostest.rosrun("hrg_gyro", "calibration_wave_lag", WaveLag)
