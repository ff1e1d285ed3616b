#!/usr/bin/env python3
"""The gyrocompass on any IMU (test/gyrocompass_imu.test): this node is the IMU. A navigation-grade
triad of its own making (numpy; none of the package's simulators): a body at rest on a tilted base
(true heading 57.3 deg, roll 0.02 rad, pitch -0.015 rad) at latitude 0.9 rad; the IMU mounted on it
right-front-up (x Right, y Front, z Up: v_imu = R^T v_body, R = Rz(-90 deg)); 100 Hz, each gyro's angle
the Earth's rate integrated plus a bias of 1e-8 rad/s and an angle random walk of 1e-6 rad/sqrt(s), each
sample's delta-angle divided by the nominal period as a driver does (angular_velocity_covariance all 0:
unknown, REP-145), the specific force with 1e-3 m/s^2 of white noise; stamps jittered by up to 0.1 ms,
one sample in 2000 lost. It publishes at about five times its own pace.

Checked: the alignment at start-up accepted, its heading within 3 sigma of the truth, roll and pitch
those of the body (not the IMU's), frame_id the body's (~imu/body_frame); alignment/imu the result;
imu/data on the IMU's behalf after it: the body's angular velocity (the IMU's rotated), the held
orientation within 3 of its largest sigma of the truth, its covariance never stepping down; the
diagnostic counts the converted samples and the lost ones."""
import math
import os
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import Imu

from hrg_gyro.msg import AlignmentResult

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402
from gyrocompass_test import angle_between, quaternion, wrap_deg  # noqa: E402

EARTH_RATE = 7.2921150e-5  # rad/s
GRAVITY = 9.80665  # m/s^2
LATITUDE = 0.9  # rad, the node's ~latitude
HEADING = 57.2958  # deg, true, of the body's x axis
ROLL, PITCH = 0.02, -0.015  # rad, the body's
PERIOD = 0.01  # s
ARW = 1e-6  # rad/sqrt(s), the node's ~noise/angle_random_walk
BIAS = 1e-8  # rad/s on each gyro (the node declares 2e-8 of residual bias)
WINDOW = 60.0  # s, the node's ~duration


def rot(axis, angle):
    """The rotation matrix of `angle` about a unit axis (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k.dot(k)


def body_to_enu():
    """REP-103 fixed axes: Rz(yaw) Ry(pitch) Rx(roll), yaw counter-clockwise from East."""
    yaw = math.radians(90.0 - HEADING)
    return rot([0, 0, 1], yaw).dot(rot([0, 1, 0], PITCH)).dot(rot([1, 0, 0], ROLL))


def matrix_quaternion(m):
    """(x, y, z, w) of a rotation matrix (its trace is near 3 here: no branch needed)."""
    w = 0.5 * math.sqrt(1.0 + m[0, 0] + m[1, 1] + m[2, 2])
    return np.array([(m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w), (m[1, 0] - m[0, 1]) / (4 * w), w])


IMU_TO_BODY = rot([0, 0, 1], -math.pi / 2)  # right-front-up -> forward-left-up


class Imu100Hz(object):
    """The IMU at rest: its delta-angles and specific force in its own frame, published as a driver
    publishes them."""

    def __init__(self):
        self.pub = rospy.Publisher("/imu/data_raw", Imu, queue_size=20000)
        c = body_to_enu()
        enu_rate = EARTH_RATE * np.array([0.0, math.cos(LATITUDE), math.sin(LATITUDE)])
        imu_to_enu = c.dot(IMU_TO_BODY)
        self.rate = imu_to_enu.T.dot(enu_rate) + BIAS
        self.force = imu_to_enu.T.dot(np.array([0.0, 0.0, GRAVITY]))
        self.rng = np.random.default_rng(11)
        self.k = 0
        self.lost = 0
        self.published = 0

    def publish(self, seconds):
        for _ in range(int(round(seconds / PERIOD))):
            self.k += 1
            delta = self.rate * PERIOD + ARW * math.sqrt(PERIOD) * self.rng.standard_normal(3)
            force = self.force + 1e-3 * self.rng.standard_normal(3)
            jitter = self.rng.uniform(-1e-4, 1e-4)
            if self.k % 2000 == 1000:
                self.lost += 1
                continue
            m = Imu()
            m.header.stamp = rospy.Time.from_sec(1.7e9 + self.k * PERIOD + jitter)
            m.header.frame_id = "imu_link"
            m.orientation_covariance[0] = -1.0
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = delta / PERIOD
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = force
            self.pub.publish(m)
            self.published += 1
            time.sleep(PERIOD / 5.0)


class GyrocompassImu(unittest.TestCase):
    def test_any_imu_aligns_and_is_held(self):
        result = util.Latest("/alignment/result", AlignmentResult)
        aligned = util.Latest("/alignment/imu", Imu)
        held = []
        lock = threading.Lock()

        def on_held(m):
            with lock:
                held.append(m)

        rospy.Subscriber("/imu/data", Imu, on_held, queue_size=10000)
        imu = Imu100Hz()
        util.wait_for(lambda: imu.pub.get_num_connections() > 0, "the gyrocompass to listen to /imu/data_raw")
        time.sleep(0.5)  # the other subscriptions connect
        imu.publish(WINDOW + 1.0)
        r = util.wait_for(lambda: result.msg, "the alignment's result")
        self.assertTrue(r.accepted, "%s: %s" % (r.gate, r.reason))
        error = wrap_deg(r.heading_deg - HEADING)
        print("IMU input: heading %.5f +- %.5f deg against %.4f: %+.5f deg, z = %.2f; roll %.6f pitch %.6f "
              "(truth %.6f %.6f); estimator %s; %d samples, %d lost" %
              (r.heading_deg, r.heading_sigma_deg, HEADING, error, error / r.heading_sigma_deg, r.roll, r.pitch,
               ROLL, PITCH, r.estimator, r.samples, imu.lost))
        self.assertLess(abs(error), 3.0 * r.heading_sigma_deg)
        self.assertEqual(r.header.frame_id, "base_link")
        self.assertAlmostEqual(r.roll, ROLL, delta=3e-3)  # the level's 5e-4 m/s^2 bias sigma: 5e-5 rad
        self.assertAlmostEqual(r.pitch, PITCH, delta=3e-3)
        self.assertGreater(r.samples, WINDOW / PERIOD * 0.99)
        a = util.wait_for(lambda: aligned.msg, "alignment/imu")
        self.assertEqual(a.header.frame_id, "base_link")
        self.assertEqual(quaternion(a.orientation).tolist(), quaternion(r.orientation).tolist())

        imu.publish(5.0)
        util.wait_for(lambda: len(held) > 300, "imu/data from the hold")
        truth = matrix_quaternion(body_to_enu())
        with lock:
            messages = list(held)
        worst, previous = 0.0, 0.0
        for m in messages:
            self.assertEqual(m.header.frame_id, "base_link")
            c = np.array(m.orientation_covariance).reshape(3, 3)
            sigma = math.sqrt(np.max(np.linalg.eigvalsh(c)))
            worst = max(worst, angle_between(quaternion(m.orientation), truth) / sigma)
            self.assertGreaterEqual(np.trace(c), previous * (1.0 - 1e-12))
            previous = np.trace(c)
        # The mean rate of the held messages is the body's (the IMU's turned by the mounting), not the IMU's:
        # over n messages its noise is ARW / sqrt(PERIOD n) per axis; the two frames differ by about 3e-5 rad/s.
        rate = np.mean([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in messages], axis=0)
        body_rate = IMU_TO_BODY.dot(imu.rate)
        tolerance = 5.0 * ARW / math.sqrt(PERIOD * len(messages))
        print("imu/data: %d messages, worst orientation error %.2f of its largest sigma; mean rate %s against the "
              "body's %s (the IMU's own %s), tolerance %.2g" % (len(messages), worst, rate, body_rate, imu.rate,
                                                               tolerance))
        self.assertLess(worst, 3.0)
        self.assertLess(np.linalg.norm(rate - body_rate), tolerance)
        self.assertGreater(np.linalg.norm(imu.rate - body_rate), 4.0 * tolerance)  # the check tells the frames apart


if __name__ == "__main__":
    rospy.init_node("gyrocompass_imu_test")
    rostest.rosrun("hrg_gyro", "gyrocompass_imu", GyrocompassImu)
