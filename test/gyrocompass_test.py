#!/usr/bin/env python3
"""The simulated triad at rest and the gyrocompass in one nodelet manager (test/gyrocompass.test).

~align starts a 30 s window; alignment/result is checked against the scenario's truth (latitude 0.9
rad, the body's x axis at azimuth 1.0 rad from North, level): the heading within 3 of its sigmas, and
the sigma itself against the one the triad's own noise predicts. The white angle noise q per sample of
each horizontal axis is measured here from the triad's increments over the window (at rest an
increment is w dt + n_k - n_(k-1): its variance is 2 q^2); a straight line fitted to the N integrated
angles over T s has a slope of standard error q sqrt(12 / N) / T, and the heading, with the body level,
an error of that over the horizontal Earth rate Omega cos(lat). The budget's noise term must lie within
a factor of 2 of it (the node fits the same noise, measured its own way); its residual-bias term is the
declared 1e-8 rad/s over that rate, and the sigma the two together. alignment/imu carries the
result's orientation and covariance with the -1 markers; imu/data after it the held attitude, near the
result's, its covariance never stepping down, the tilts' growing by the bias. The diagnostics say so; ~align is refused while one runs,
and a second gyrocompass at a site beyond ~max_latitude refuses at once, naming the gate."""
import math
import os
import sys
import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import Imu

from hrg_gyro.msg import AlignmentResult, BodyTruth, TriadOutput
from hrg_gyro.srv import StartAlignment

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

EARTH_RATE = 7.2921150e-5  # rad/s
WINDOW = 30.0  # s of gyro stamps
HOLD = 5.0  # s of the held attitude checked
RESIDUAL_BIAS = 1e-8  # rad/s, the gyrocompass's ~noise/residual_bias (gyrocompass.test)


def quaternion(q):
    return np.array([q.x, q.y, q.z, q.w])


def angle_between(a, b):
    """rad between two unit quaternions (x, y, z, w): 2 atan2(|v|, |w|) of a^-1 b, exact for small angles
    (2 acos(a . b) cannot resolve less than 3e-8 rad: a . b rounds to 1 or to 1 - 1.1e-16)."""
    ax, ay, az, aw = -a[0], -a[1], -a[2], a[3]  # the conjugate
    bx, by, bz, bw = b
    v = np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                  aw * bz + ax * by - ay * bx + az * bw])
    w = aw * bw - ax * bx - ay * by - az * bz
    return 2.0 * math.atan2(float(np.linalg.norm(v)), abs(w))


def rpy_quaternion(roll, pitch, yaw):
    """Rz(yaw) Ry(pitch) Rx(roll) as (x, y, z, w)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
                     cr * cp * cy + sr * sp * sy])


def wrap_deg(d):
    return (d + 180.0) % 360.0 - 180.0


class Statuses(object):
    """The latest /diagnostics status of each exact name."""

    def __init__(self):
        self._lock = threading.Lock()
        self.status = {}
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self._on, queue_size=100)

    def _on(self, msg):
        with self._lock:
            for s in msg.status:
                self.status[s.name] = s

    def get(self, name):
        with self._lock:
            return self.status.get(name)


class Gyrocompass(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        scenario = util.load_yaml(rospy.get_param("~scenario"))["triad"]
        cls.latitude = scenario["turntable"]["latitude"]
        cls.azimuth = scenario["turntable"]["azimuth"]
        cls.diagnostics = Statuses()
        cls.triad = util.Latest("/triad/output", TriadOutput, keep_all=True)
        cls.held = util.Latest("/imu/data", Imu, keep_all=True)
        cls.result = util.Latest("/alignment/result", AlignmentResult)
        cls.imu = util.Latest("/alignment/imu", Imu)
        cls.polar_result = util.Latest("/polar/alignment/result", AlignmentResult)
        cls.levelled = util.Latest("/levelled/alignment/result", AlignmentResult)
        cls.truth = util.Latest("/truth", BodyTruth)  # the driver starts once this listens
        util.wait_for_service("/gyrocompass/align")
        util.wait_for_service("/polar/gyrocompass/align")
        align = rospy.ServiceProxy("/gyrocompass/align", StartAlignment)
        cls.started = align(duration=WINDOW, mode="")
        cls.again = align(duration=WINDOW, mode="")  # while the first runs
        cls.polar = rospy.ServiceProxy("/polar/gyrocompass/align", StartAlignment)(duration=0.0, mode="")
        util.wait_for(lambda: cls.result.msg is not None, "alignment/result")
        r = cls.result.msg
        util.wait_for(lambda: cls.imu.msg is not None, "alignment/imu")
        end = r.window_end.to_sec()
        util.wait_for(lambda: cls.held.all and cls.held.all[-1].header.stamp.to_sec() > end + HOLD,
                      "%.0f s of imu/data after the window's end" % HOLD)
        util.wait_for(lambda: cls.polar_result.msg is not None, "polar/alignment/result")
        util.wait_for(lambda: cls.levelled.msg is not None, "levelled/alignment/result")

    def test_the_service_starts_one_and_refuses_a_second_while_it_runs(self):
        self.assertTrue(self.started.success, self.started.message)
        self.assertIn("30", self.started.message)
        self.assertFalse(self.again.success)
        self.assertIn("an alignment runs", self.again.message)

    def test_a_site_beyond_max_latitude_is_refused_at_once(self):
        self.assertFalse(self.polar.success)
        self.assertIn("latitude", self.polar.message)
        r = self.polar_result.msg
        self.assertFalse(r.accepted)
        self.assertEqual(r.gate, "latitude")
        self.assertIn("max_latitude", r.reason)

    def test_the_heading_is_the_truth_within_its_sigma(self):
        r = self.result.msg
        self.assertTrue(r.accepted, "%s: %s" % (r.gate, r.reason))
        self.assertEqual(r.gate, "")
        self.assertEqual(r.mode, "static")
        self.assertFalse(r.single_gyro)
        self.assertEqual(r.frame, "body")
        self.assertEqual(r.header.frame_id, "imu_link")
        self.assertEqual(r.header.stamp, r.window_end)
        self.assertAlmostEqual(r.seconds, WINDOW, delta=0.01)
        self.assertAlmostEqual((r.window_end - r.window_start).to_sec(), WINDOW, delta=0.01)
        self.assertGreater(r.samples, 0.99 * WINDOW * 200)
        truth = math.degrees(self.azimuth)
        error = wrap_deg(r.heading_deg - truth)
        rospy.loginfo("gyrocompass: heading %.5f deg (truth %.5f): error %.5f deg = %.2f sigma, sigma %.5f deg",
                      r.heading_deg, truth, error, error / r.heading_sigma_deg, r.heading_sigma_deg)
        self.assertGreater(r.heading_sigma_deg, 0.0)
        self.assertLess(abs(error), 3.0 * r.heading_sigma_deg)
        # REP-103: yaw from East, counter-clockwise; the declared exact level.
        self.assertAlmostEqual(r.yaw, math.pi / 2 - math.radians(r.heading_deg), delta=1e-12)
        self.assertEqual(r.roll, 0.0)
        self.assertEqual(r.pitch, 0.0)
        expected = rpy_quaternion(r.roll, r.pitch, r.yaw)
        self.assertLess(angle_between(quaternion(r.orientation), expected), 1e-12)
        self.assertLess(angle_between(quaternion(r.body_orientation), expected), 1e-12)
        # The covariance: symmetric, the heading's variance its sigma squared, the budget's total its sigma.
        c = np.array(r.orientation_covariance).reshape(3, 3)
        self.assertTrue(np.allclose(c, c.T, rtol=0, atol=1e-30))
        self.assertAlmostEqual(c[2, 2] / math.radians(r.heading_sigma_deg) ** 2, 1.0, delta=1e-9)
        e = np.array(r.euler_covariance).reshape(3, 3)
        self.assertAlmostEqual(e[2, 2] / c[2, 2], 1.0, delta=1e-9)  # level body: yaw error is the ENU z
        self.assertAlmostEqual(r.budget_total / math.radians(r.heading_sigma_deg), 1.0, delta=1e-9)
        self.assertGreater(r.budget_noise, 0.0)
        self.assertEqual(r.budget_level, 0.0)  # exact declared level
        # The Earth's horizontal rate measured is the site's.
        h = EARTH_RATE * math.cos(self.latitude)
        self.assertAlmostEqual(r.expected_horizontal_rate / h, 1.0, delta=1e-6)
        self.assertEqual(r.latitude, self.latitude)
        self.assertLess(abs(r.horizontal_rate - h), 4.0 * r.horizontal_rate_std + 1e-3 * h)
        self.assertTrue(r.segment_start and len(r.segment_start) == len(r.segment_end) == len(r.segment_rms_ratio))

    def test_an_accelerometer_levels_the_alignment_at_startup(self):
        # The second gyrocompass: ~align_at_startup, level from accel/data_raw (bias 4.9e-4, -3.2e-4
        # m/s^2, declared ~level/accelerometer_bias_sigma 5e-4): its window is the session's first 30 s.
        r = self.levelled.msg
        self.assertTrue(r.accepted, "%s: %s" % (r.gate, r.reason))
        self.assertEqual(r.mode, "static")
        first = self.triad.all[0].header.stamp
        self.assertLess(abs((r.window_start - first).to_sec()), 0.006, "the window starts with the first sample")
        self.assertAlmostEqual(r.seconds, WINDOW, delta=0.01)
        truth = math.degrees(self.azimuth)
        error = wrap_deg(r.heading_deg - truth)
        e = np.array(r.euler_covariance).reshape(3, 3)
        roll_sigma, pitch_sigma = math.sqrt(e[0, 0]), math.sqrt(e[1, 1])
        rospy.loginfo("levelled gyrocompass: heading error %.5f deg = %.2f sigma (sigma %.5f deg, level %.2e rad); "
                      "roll %.2e +- %.1e, pitch %.2e +- %.1e rad (truth 0)", error, error / r.heading_sigma_deg,
                      r.heading_sigma_deg, r.budget_level, r.roll, roll_sigma, r.pitch, pitch_sigma)
        self.assertLess(abs(error), 3.0 * r.heading_sigma_deg)
        # The level is measured (the accelerometer's bias tilts it by about bias / g) within its sigma,
        # and its error enters the heading's budget times tan(latitude).
        self.assertNotEqual(r.roll, 0.0)
        self.assertNotEqual(r.pitch, 0.0)
        self.assertLess(abs(r.roll), 3.0 * roll_sigma)
        self.assertLess(abs(r.pitch), 3.0 * pitch_sigma)
        self.assertGreater(roll_sigma, 0.9 * 5e-4 / 9.80665)
        self.assertGreater(r.budget_level, 0.0)

    def test_the_sigma_is_what_the_triads_noise_predicts(self):
        r = self.result.msg
        start, end = r.window_start.to_nsec(), r.window_end.to_nsec()
        window = [m for m in self.triad.all if start < m.header.stamp.to_nsec() <= end and m.flags == 0]
        self.assertGreater(len(window), 0.99 * WINDOW * 200)
        n, seconds = len(window), WINDOW
        q = [np.std([getattr(m.delta_angle, axis) for m in window]) / math.sqrt(2.0) for axis in "xy"]
        slope = math.sqrt(np.mean(np.square(q))) * math.sqrt(12.0 / n) / seconds
        predicted = math.degrees(slope / (EARTH_RATE * math.cos(self.latitude)))
        noise = math.degrees(r.budget_noise)
        rospy.loginfo("gyrocompass: white angle noise %.3g %.3g rad per sample; noise term %.5f deg, predicted %.5f deg",
                      q[0], q[1], noise, predicted)
        self.assertGreater(noise, 0.5 * predicted)
        self.assertLess(noise, 2.0 * predicted)
        h = EARTH_RATE * math.cos(self.latitude)
        self.assertAlmostEqual(r.budget_residual_bias / (RESIDUAL_BIAS / h), 1.0, delta=1e-6)
        self.assertAlmostEqual(r.budget_total / math.hypot(r.budget_noise, r.budget_residual_bias), 1.0, delta=1e-9)

    def test_alignment_imu_is_the_result_for_a_navigation_filter(self):
        r, m = self.result.msg, self.imu.msg
        self.assertEqual(m.header.frame_id, "imu_link")
        self.assertEqual(m.header.stamp, r.window_end)
        self.assertEqual(quaternion(m.orientation).tolist(), quaternion(r.body_orientation).tolist())
        self.assertEqual(quaternion(m.orientation).tolist(), quaternion(r.orientation).tolist())  # static: the body
        self.assertEqual(list(m.orientation_covariance), list(r.orientation_covariance))
        self.assertEqual(m.angular_velocity_covariance[0], -1.0)
        self.assertEqual(m.linear_acceleration_covariance[0], -1.0)

    def test_imu_data_holds_the_attitude_with_a_growing_covariance(self):
        r = self.result.msg
        end = r.window_end.to_nsec()
        held = [m for m in self.held.all if m.header.stamp.to_sec() <= r.window_end.to_sec() + HOLD]
        self.assertGreater(len(held), 0.9 * HOLD * 200)
        self.assertGreater(held[0].header.stamp.to_nsec(), end)
        triad = dict((m.header.stamp.to_nsec(), m) for m in self.triad.all)
        sigma = math.radians(r.heading_sigma_deg)
        previous = None
        for m in held:
            self.assertEqual(m.header.frame_id, "imu_link")
            self.assertLess(angle_between(quaternion(m.orientation), quaternion(r.orientation)), 3.0 * sigma)
            c = np.array(m.orientation_covariance).reshape(3, 3)
            self.assertTrue(np.all(np.linalg.eigvalsh(0.5 * (c + c.T)) > 0.0))
            if previous is not None:  # never a step down (beyond rounding)
                for i in (0, 1, 2):
                    self.assertGreaterEqual(c[i, i], previous[i, i] * (1.0 - 1e-9))
            previous = c
            t = triad.get(m.header.stamp.to_nsec())
            self.assertIsNotNone(t, "imu/data at a stamp the triad did not publish")
            self.assertEqual(list(m.angular_velocity_covariance), list(t.angular_velocity_covariance))
            self.assertEqual(m.angular_velocity.z, t.angular_velocity.z)
            self.assertEqual(m.linear_acceleration_covariance[0], -1.0)
        # It starts from the aligned attitude's covariance; the bias tilts it (the tilts' variances grow
        # as b^2 t^2), while the heading's, whose error the static alignment took from that same bias,
        # holds over seconds (the Earth's rate turns the East tilt into heading, against it).
        first = np.array(held[0].orientation_covariance).reshape(3, 3)
        rospy.loginfo("gyrocompass: hold covariance diagonal %s after %.3f s, %s after %.3f s", np.diag(first),
                      held[0].header.stamp.to_sec() - r.window_end.to_sec(), np.diag(previous),
                      held[-1].header.stamp.to_sec() - r.window_end.to_sec())
        self.assertGreaterEqual(first[2, 2], r.orientation_covariance[8] * (1.0 - 1e-9))
        self.assertGreater(previous[0, 0], first[0, 0])
        self.assertGreater(previous[1, 1], first[1, 1])
        self.assertAlmostEqual(previous[2, 2] / first[2, 2], 1.0, delta=1e-6)

    def test_the_diagnostics_report_the_result_and_the_hold(self):
        compass = util.wait_for(lambda: self._status("gyrocompass: gyrocompass", "heading"),
                                "the gyrocompass diagnostic with the heading")
        self.assertEqual(compass.level, DiagnosticStatus.OK)
        self.assertIn("%.4f" % self.result.msg.heading_deg, compass.message)
        values = dict((kv.key, kv.value) for kv in compass.values)
        self.assertEqual(values["last accepted"], "true")
        self.assertIn("budget total rad", values)
        hold = util.wait_for(lambda: self._status("gyrocompass: attitude hold", "holding"), "the hold's diagnostic")
        self.assertEqual(hold.level, DiagnosticStatus.OK)
        polar = util.wait_for(lambda: self._status("polar/gyrocompass: gyrocompass", "refused"),
                              "the polar gyrocompass's refusal")
        self.assertEqual(polar.level, DiagnosticStatus.ERROR)
        self.assertIn("latitude", polar.message)

    def _status(self, name, word):
        s = self.diagnostics.get(name)
        return s if s is not None and word in s.message else None


if __name__ == "__main__":
    rospy.init_node("gyrocompass_test")
    rostest.rosrun("hrg_gyro", "gyrocompass", Gyrocompass)
