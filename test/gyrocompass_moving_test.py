#!/usr/bin/env python3
"""The gyrocompass live on a standing vehicle whose engine runs (test/gyrocompass_moving.test).

The gyrocompass aligns at start-up over 120 s, levelled by the simulated accelerometer. The base sways
and vibrates, so the still-base fit cannot answer and the tracking estimator must (the gyros track the
body, gravity followed in the inertial frame): alignment/result says so and why. Its heading is the
truth's at the window's last sample (BodyTruth.body_to_enu, the base's motion included) within 3 of its
sigmas; its orientation is its roll, pitch and yaw, its covariance symmetric and positive, the heading's
variance its sigma squared, the budget's total its sigma; the three checks against the Earth passed,
each within its limit; the noise sources are the noise file's. alignment/imu carries the same
orientation and covariance at the last sample's stamp with REP-145's markers. imu/data then holds the
moving body's attitude within 3 sigmas of the truth at each stamp, its covariance never stepping down."""
import math
import os
import sys
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import Imu

from hrg_gyro.msg import AlignmentResult, BodyTruth, TriadOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402
from gyrocompass_test import angle_between, quaternion, rpy_quaternion, wrap_deg  # noqa: E402

WINDOW = 120.0  # s, gyrocompass.launch duration
HOLD = 5.0  # s of the held attitude checked
MAX_EARTH_SIGMAS = 5.0  # config/gyrocompass.yaml


def heading_deg(q):
    """The true heading (deg, clockwise from North) of a body -> ENU quaternion (x, y, z, w)."""
    x, y, z, w = q
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return (90.0 - math.degrees(yaw)) % 360.0


class GyrocompassMoving(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = util.Latest("/truth", BodyTruth, keep_all=True)  # the driver starts once this listens
        cls.triad = util.Latest("/triad/output", TriadOutput, keep_all=True)
        cls.held = util.Latest("/imu/data", Imu, keep_all=True)
        cls.result = util.Latest("/alignment/result", AlignmentResult)
        cls.imu = util.Latest("/alignment/imu", Imu)
        util.wait_for(lambda: cls.result.msg is not None, "alignment/result")
        util.wait_for(lambda: cls.imu.msg is not None, "alignment/imu")
        end = cls.result.msg.last_sample.to_sec()
        util.wait_for(lambda: cls.held.all and cls.held.all[-1].header.stamp.to_sec() > end + HOLD,
                      "%.0f s of imu/data after the window's end" % HOLD)
        util.wait_for(lambda: cls.truth.all and cls.truth.all[-1].header.stamp.to_sec() > end + HOLD,
                      "the truth past the hold")
        cls.truth_at = dict((m.header.stamp.to_nsec(), quaternion(m.body_to_enu)) for m in cls.truth.all)

    def test_the_tracking_estimator_answers_within_its_sigma(self):
        r = self.result.msg
        self.assertTrue(r.accepted, "%s: %s" % (r.gate, r.reason))
        self.assertEqual(r.estimator, "tracking")
        self.assertIn("not still", r.estimator_reason)
        self.assertEqual((r.mode, r.frame, r.header.frame_id), ("static", "body", "imu_link"))
        self.assertAlmostEqual((r.window_end - r.window_start).to_sec(), WINDOW, delta=0.01)
        self.assertLessEqual(r.last_sample, r.window_end)
        self.assertGreater(r.last_sample.to_sec(), r.window_end.to_sec() - 0.01)
        truth = self.truth_at.get(r.last_sample.to_nsec())
        self.assertIsNotNone(truth, "no truth at the last sample's stamp")
        error = wrap_deg(r.heading_deg - heading_deg(truth))
        rospy.loginfo("gyrocompass on a moving base: heading %.5f deg (truth %.5f at the last sample): error %.5f deg = "
                      "%.2f sigma, sigma %.5f deg; %s", r.heading_deg, heading_deg(truth), error,
                      error / r.heading_sigma_deg, r.heading_sigma_deg, r.estimator_reason)
        print("[ measured ] live, moving base, 120 s: error %+.3f mrad, sigma %.3f mrad (z %+.2f)" %
              (math.radians(error) * 1e3, math.radians(r.heading_sigma_deg) * 1e3, error / r.heading_sigma_deg))
        self.assertLess(abs(error), 3.0 * r.heading_sigma_deg)
        # The whole attitude, not only its heading: within 3 sigmas of its largest axis.
        c = np.array(r.orientation_covariance).reshape(3, 3)
        self.assertLess(angle_between(quaternion(r.orientation), truth), 3.0 * math.sqrt(np.max(np.linalg.eigvalsh(c))))

    def test_the_result_agrees_with_itself_field_by_field(self):
        r = self.result.msg
        self.assertAlmostEqual(r.yaw, math.pi / 2 - math.radians(r.heading_deg), delta=1e-9)
        self.assertLess(angle_between(quaternion(r.orientation), rpy_quaternion(r.roll, r.pitch, r.yaw)), 1e-9)
        self.assertEqual(quaternion(r.body_orientation).tolist(), quaternion(r.orientation).tolist())  # static
        c = np.array(r.orientation_covariance).reshape(3, 3)
        self.assertTrue(np.allclose(c, c.T, rtol=0, atol=1e-30))
        self.assertTrue(np.all(np.linalg.eigvalsh(0.5 * (c + c.T)) > 0.0))
        e = np.array(r.euler_covariance).reshape(3, 3)
        self.assertAlmostEqual(e[2, 2] / math.radians(r.heading_sigma_deg) ** 2, 1.0, delta=1e-9)
        self.assertAlmostEqual(r.budget_total / math.radians(r.heading_sigma_deg), 1.0, delta=1e-9)
        self.assertGreater(r.budget_noise, r.budget_residual_bias)  # the accelerometer's noise limits it
        self.assertEqual(list(r.check_name), ["length", "vertical", "angle"])
        for name, measured, expected, sigma, passed in zip(r.check_name, r.check_measured, r.check_expected,
                                                          r.check_sigma, r.check_passed):
            self.assertTrue(passed, name)
            self.assertLessEqual(abs(measured - expected), MAX_EARTH_SIGMAS * sigma, name)
        self.assertIn("settings", r.noise_sources)
        self.assertGreater(r.low_frequency_scatter, 0.0)

    def test_alignment_imu_is_the_result_at_its_last_sample(self):
        r, m = self.result.msg, self.imu.msg
        self.assertEqual(m.header.frame_id, "imu_link")
        self.assertEqual(m.header.stamp, r.last_sample)
        self.assertEqual(quaternion(m.orientation).tolist(), quaternion(r.body_orientation).tolist())
        self.assertEqual(list(m.orientation_covariance), list(r.orientation_covariance))
        self.assertEqual(m.angular_velocity_covariance[0], -1.0)
        self.assertEqual(m.linear_acceleration_covariance[0], -1.0)

    def test_imu_data_holds_the_moving_bodys_attitude(self):
        r = self.result.msg
        end = r.last_sample.to_sec()
        held = [m for m in self.held.all if m.header.stamp.to_sec() <= end + HOLD]
        self.assertGreater(len(held), 0.9 * HOLD * 200)
        previous, worst = None, 0.0
        for m in held:
            truth = self.truth_at.get(m.header.stamp.to_nsec())
            self.assertIsNotNone(truth, "no truth at a held stamp")
            c = np.array(m.orientation_covariance).reshape(3, 3)
            sigma = math.sqrt(np.max(np.linalg.eigvalsh(0.5 * (c + c.T))))
            worst = max(worst, angle_between(quaternion(m.orientation), truth) / sigma)
            # The Earth's rate turns the covariance in ENU (a tilt's variance may pass to the other):
            # its trace, which the turn keeps, never steps down, nor a diagonal entry beyond the turn's share.
            if previous is not None:
                self.assertGreaterEqual(np.trace(c), np.trace(previous) * (1.0 - 1e-12))
                for i in (0, 1, 2):
                    self.assertGreaterEqual(c[i, i], previous[i, i] * (1.0 - 1e-6))
            previous = c
        print("[ measured ] live, moving base: the held attitude's worst error over its largest sigma in %.0f s: %.2f" %
              (HOLD, worst))
        self.assertLess(worst, 3.0)


if __name__ == "__main__":
    rospy.init_node("gyrocompass_moving_test")
    rostest.rosrun("hrg_gyro", "gyrocompass_moving", GyrocompassMoving)
