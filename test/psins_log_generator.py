#!/usr/bin/env python3
"""A navigation-grade IMU at rest, written as a PSINS "SIMU" text log (the format of the PSINS toolbox's
logs, which `hrg_bag import --format psins` reads), with its truth: an independent generator (numpy,
none of the package's code) for the tests of the IMU log's import and of north-finding from it.

The log: comment lines starting with '%', then three header lines
  pitch0 roll0 yaw0 (deg; yaw0 counter-clockwise from North, as PSINS writes it) VE0 VN0 VU0 (m/s)
  lat0 lon0 (deg) h0 (m) t0 (s) sampling interval (ms) g (m/s^2)
  gyro counts (arcsec) x3, accelerometer counts (ug*s) x3
then one row per sample of six integers: the gyros' angle increments and the accelerometers' velocity
increments in counts, axes x Right, y Forward, z Up (the PSINS convention).

Model (REP-103/105): ENU at latitude lat, the Earth's rate W = Omega (0, cos lat, sin lat), Omega =
7.292115e-5 rad/s; the body forward-left-up with a true heading H of its x axis (clockwise from North),
a pitch p and a roll r: body -> ENU = Rz(90 deg - H) Ry(p) Rx(r); the IMU on it right-front-up, IMU ->
body = Rz(-90 deg). Each gyro's angle: (R^T W + bias) t plus an angle random walk; each accelerometer's
velocity: R^T (0, 0, g) t plus white noise per sample. Both are counted: the count each sample is the
change of the rounded accumulated quantity (the remainder carried, as an IMU's counter does), so the
angle the counts sum to is within half a count of the true one at every sample.
Truth (--truth FILE, YAML): heading_deg, roll, pitch (rad, of the body), latitude (rad), the gyro bias
(rad/s, IMU axes), the angle random walk (rad/sqrt(s)), the quanta (rad, m/s)."""
import argparse
import math

import numpy as np

OMEGA = 7.292115e-5  # rad/s
ARCSEC = math.pi / 180.0 / 3600.0


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True)
    p.add_argument("--truth", default="")
    p.add_argument("--seconds", type=float, default=600.0)
    p.add_argument("--interval-ms", type=float, default=10.0)
    p.add_argument("--heading", type=float, default=90.6, help="deg, true, of the body's x (the IMU's y)")
    p.add_argument("--pitch", type=float, default=0.015, help="rad, REP-103, of the body")
    p.add_argument("--roll", type=float, default=0.006, help="rad")
    p.add_argument("--latitude", type=float, default=34.246048, help="deg")
    p.add_argument("--longitude", type=float, default=108.909664, help="deg")
    p.add_argument("--height", type=float, default=380.0, help="m")
    p.add_argument("--gravity", type=float, default=9.780327, help="m/s^2")
    p.add_argument("--gyro-count", type=float, default=0.1, help="arcsec per count")
    p.add_argument("--accel-count", type=float, default=125.0, help="ug*s per count")
    p.add_argument("--arw", type=float, default=5e-7, help="rad/sqrt(s) per gyro")
    p.add_argument("--bias", type=float, nargs=3, default=[3e-8, -2e-8, 1e-8], help="rad/s per IMU axis")
    p.add_argument("--accel-noise", type=float, default=2e-3, help="m/s^2 per sample")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()

    dt = a.interval_ms / 1000.0
    n = int(round(a.seconds / dt))
    lat = math.radians(a.latitude)
    body_to_enu = rot_z(math.radians(90.0 - a.heading)).dot(rot_y(a.pitch)).dot(rot_x(a.roll))
    imu_to_enu = body_to_enu.dot(rot_z(-math.pi / 2.0))
    rate = imu_to_enu.T.dot(OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])) + np.array(a.bias)
    force = imu_to_enu.T.dot(np.array([0.0, 0.0, a.gravity]))
    q_angle = a.gyro_count * ARCSEC
    q_velocity = a.accel_count * 1e-6 * a.gravity
    rng = np.random.default_rng(a.seed)
    k = np.arange(1, n + 1)[:, None]
    angle = rate[None, :] * dt * k + np.cumsum(a.arw * math.sqrt(dt) * rng.standard_normal((n, 3)), axis=0)
    velocity = force[None, :] * dt * k + np.cumsum(a.accel_noise * dt * rng.standard_normal((n, 3)), axis=0)
    gyro_counts = np.diff(np.round(angle / q_angle), axis=0, prepend=0.0).astype(np.int64)
    accel_counts = np.diff(np.round(velocity / q_velocity), axis=0, prepend=0.0).astype(np.int64)

    with open(a.out, "w") as f:
        f.write("%% PSINS-format SIMU log file, written by hrg_gyro's test/psins_log_generator.py (seed %d).\n" % a.seed)
        f.write("% 1st line: [pitch0(deg), roll0(deg), yaw0(deg), VE0(m/s), VN0(m/s), VU0(m/s)].\n")
        f.write("% 2nd line: [latitude0(deg), longitude0(deg), height0(m), t0(s), sampling-interval(ms), g(m/s^2)].\n")
        f.write("% 3rd line: [gf_x, gf_y, gf_z, af_x, af_y, af_z]: gyro counts in arcsec, accelerometer in ug*s.\n")
        f.write("% Axes: X-Right, Y-Forward, Z-Up.\n\n")
        f.write("%.6f %.6f %.6f 0.000000 0.000000 0.000000\n" % (math.degrees(a.pitch), math.degrees(a.roll), -a.heading))
        f.write("%.8f %.8f %.3f 0.00000000 %.8f %.6f\n" % (a.latitude, a.longitude, a.height, a.interval_ms, a.gravity))
        f.write("%.6f %.6f %.6f %.3f %.3f %.3f \n" % ((a.gyro_count,) * 3 + (a.accel_count,) * 3))
        for g, v in zip(gyro_counts, accel_counts):
            f.write("%d %d %d %d %d %d\n" % (g[0], g[1], g[2], v[0], v[1], v[2]))
    if a.truth:
        with open(a.truth, "w") as f:
            f.write("heading_deg: %.10f\nroll: %.10f\npitch: %.10f\nlatitude: %.12f\n" %
                    (a.heading, a.roll, a.pitch, lat))
            f.write("gyro_bias: [%.6e, %.6e, %.6e]\nangle_random_walk: %.6e\n" % (tuple(a.bias) + (a.arw,)))
            f.write("angle_quantum: %.9e\nvelocity_quantum: %.9e\nsamples: %d\ninterval: %.6f\n" %
                    (q_angle, q_velocity, n, dt))


if __name__ == "__main__":
    main()
