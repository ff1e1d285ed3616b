#!/usr/bin/env python3
"""imu/data_raw follows REP-145: no orientation (covariance[0] = -1), no acceleration, z the
compensated inertial rate agreeing with GyroOutput.rate, x and y unmeasured (huge variance),
frame_id as configured. The unmeasured fields hold zeros, as docs/ros_api.md's table of what the
message carries says (a filter that needs an accelerometer gets none from it)."""
import os
import sys
import unittest

import rospy
import rostest
from sensor_msgs.msg import Imu

from hrg_gyro.msg import GyroOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402


class ImuMessage(unittest.TestCase):
    def test_rep145(self):
        imu = util.Latest("/gyro/imu/data_raw", Imu, keep_all=True)
        out = util.Latest("/gyro/output", GyroOutput, keep_all=True)
        util.wait_for(lambda: imu.count > 50 and out.count > 50, "imu and output messages")
        m = imu.all[-1]
        self.assertEqual(m.header.frame_id, "gyro_link")
        self.assertEqual(m.orientation_covariance[0], -1.0)
        self.assertEqual(m.linear_acceleration_covariance[0], -1.0)
        self.assertGreaterEqual(m.angular_velocity_covariance[0], 1e5)
        self.assertGreater(m.angular_velocity_covariance[8], 0.0)
        self.assertLess(m.angular_velocity_covariance[8], 1.0)
        rates = {o.header.stamp: o.rate for o in out.all}
        matched = [i for i in imu.all if i.header.stamp in rates]
        self.assertGreater(len(matched), 20)
        for i in matched:
            self.assertEqual(i.angular_velocity.z, rates[i.header.stamp])
            self.assertEqual(i.angular_velocity.x, 0.0)
        for i in imu.all:
            self.assertEqual(i.orientation_covariance[0], -1.0)
            self.assertEqual(i.linear_acceleration_covariance[0], -1.0)
            self.assertEqual((i.orientation.x, i.orientation.y, i.orientation.z, i.orientation.w), (0.0, 0.0, 0.0, 0.0))
            self.assertEqual((i.linear_acceleration.x, i.linear_acceleration.y, i.linear_acceleration.z),
                             (0.0, 0.0, 0.0))


if __name__ == "__main__":
    rospy.init_node("imu_message_test")
    rostest.rosrun("hrg_gyro", "imu_message", ImuMessage)
