#!/usr/bin/env python3
"""An independent generator of north-finding windows, written with numpy and without the package's
simulators or its C++ test generator, so that the alignment and its tests cannot share one mistake of
frames or signs. src/core/integration/independent_alignment_test.cpp runs it and checks the gyrocompass
against the truth it writes.

Model (REP-103/105, REP-145):
  ENU local level at latitude `lat`: the Earth's rate W = Omega (0, cos lat, sin lat), Omega = 7.292115e-5
  rad/s; an accelerometer at rest reads +g up, f = (0, 0, g).
  The mount's attitude is given as the navigator gives it: a true heading H (deg, clockwise from North)
  of its x axis, a pitch p (x axis below the horizon for p > 0) and a roll r. Its rotation mount -> ENU is
  built here by turning the ENU axes in turn, about Up by 90 deg - H, about the turned y by p, about the
  twice-turned x by r (Rodrigues' formula each time).
  Static window: the triad's body is the mount. Indexed window: the body sits on an indexer platform
  whose zero frame is the mount; the platform turns about its z by psi(t): `dwell` s at 0, a move at
  0.5 rad/s to pi, `dwell` s at pi. The body's inertial rate is psi' z + R(psi)^T M^T W (M the mount's
  rotation), integrated over each 5 ms sample by ten Simpson panels.
  Each body axis: angle = the integral of its rate + bias t + white noise (sigma per sample); the
  increments are differences of that angle. The accelerometer: R^T M^T f + bias + white noise.

Files written in --out (CSV, a header line, one record per line, stamps in integer nanoseconds):
  static_gyro.csv, indexed_gyro.csv      stamp_ns,dt,dx,dy,dz        (rad over dt s, body axes)
  static_accel.csv, indexed_accel.csv    stamp_ns,fx,fy,fz           (m/s^2, body axes)
  indexed_indexer.csv                    stamp_ns,angle,rate         (rad, rad/s; 100 Hz)
  truth.csv                              key,value: latitude (rad), static_heading_deg, static_roll,
                                         static_pitch, indexed_heading_deg (the indexer's zero frame),
                                         indexed_roll, indexed_pitch (rad), static_seconds,
                                         indexed_seconds, white_noise (rad), bias_x, bias_y, bias_z (rad/s),
                                         accelerometer_bias_sigma (m/s^2)

Usage: independent_alignment.py --out DIR [--seed 1] [--latitude 0.9] [--static-seconds 120] [--dwell 60]
"""
import argparse
import math
import os

import numpy as np

OMEGA = 7.2921150e-5
G = 9.80665
RATE_HZ = 200.0


def rodrigues(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def mount_rotation(heading_deg, pitch, roll):
    """Mount -> ENU: the ENU axes turned about Up, then about the turned y, then the turned x."""
    r = rodrigues([0, 0, 1], math.radians(90.0 - heading_deg))
    r = rodrigues(r[:, 1], pitch) @ r
    r = rodrigues(r[:, 0], roll) @ r
    return r


def write_csv(path, header, rows):
    with open(path, "w") as f:
        f.write(header + "\n")
        for row in rows:
            f.write(",".join(str(int(v)) if i == 0 else repr(float(v)) for i, v in enumerate(row)) + "\n")


def rodrigues_many(axis, angles):
    """Rotations by each of `angles` about one axis (Rodrigues' formula), shape (n, 3, 3)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3)[None] + s * k[None] + (1 - c) * (k @ k)[None]


def window(rng, seconds, rate_of_body, accel_of_body, white, bias, accel_bias, start=50.0):
    """Gyro and accelerometer records of a window; rate_of_body(times) -> body rates (n, 3),
    accel_of_body(times) -> specific forces (n, 3), for arrays of times (s)."""
    n = int(round(seconds * RATE_HZ))
    h = 1.0 / RATE_HZ
    # Ten Simpson panels per sample.
    fine = np.linspace(0.0, seconds, 20 * n + 1)
    rates = rate_of_body(fine)
    weights = np.ones(21)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    increments = np.array([(weights[:, None] * rates[20 * k:20 * k + 21]).sum(axis=0) for k in range(n)])
    increments *= h / 20.0 / 3.0
    angle = np.cumsum(increments + bias * h, axis=0)
    angle = np.vstack([np.zeros(3), angle]) + white * rng.standard_normal((n + 1, 3))
    deltas = np.diff(angle, axis=0)
    times = np.arange(1, n + 1) * h
    stamps = np.round((start + times) * 1e9).astype(np.int64)
    forces = accel_of_body(times) + accel_bias + 2e-3 * rng.standard_normal((n, 3))
    gyro = [[stamps[k], h, deltas[k, 0], deltas[k, 1], deltas[k, 2]] for k in range(n)]
    accel = [[stamps[k], forces[k, 0], forces[k, 1], forces[k, 2]] for k in range(n)]
    return gyro, accel


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--latitude", type=float, default=0.9)
    parser.add_argument("--static-seconds", type=float, default=120.0)
    parser.add_argument("--dwell", type=float, default=60.0)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    lat = args.latitude
    w_enu = OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])
    f_enu = np.array([0.0, 0.0, G])
    white = 4.9e-6 / 0.56
    bias = 1e-8 * rng.standard_normal(3)
    accel_sigma = 5e-4
    truth = {"latitude": lat, "white_noise": white, "bias_x": bias[0], "bias_y": bias[1], "bias_z": bias[2],
             "accelerometer_bias_sigma": accel_sigma}

    # Static: the body is the mount.
    heading, roll, pitch = rng.uniform(0.0, 360.0), 0.01 * rng.standard_normal(), 0.01 * rng.standard_normal()
    m = mount_rotation(heading, pitch, roll)
    gyro, accel = window(rng, args.static_seconds, lambda t: np.tile(m.T @ w_enu, (len(t), 1)),
                         lambda t: np.tile(m.T @ f_enu, (len(t), 1)), white, bias, accel_sigma * rng.standard_normal(3))
    write_csv(os.path.join(args.out, "static_gyro.csv"), "stamp_ns,dt,dx,dy,dz", gyro)
    write_csv(os.path.join(args.out, "static_accel.csv"), "stamp_ns,fx,fy,fz", accel)
    truth.update({"static_heading_deg": heading, "static_roll": roll, "static_pitch": pitch,
                  "static_seconds": args.static_seconds})

    # Indexed: the body on a platform turning about the mount's z: 0, a move to pi, pi.
    heading, roll, pitch = rng.uniform(0.0, 360.0), 0.01 * rng.standard_normal(), 0.01 * rng.standard_normal()
    m = mount_rotation(heading, pitch, roll)
    dwell, move_rate = args.dwell, 0.5
    move = math.pi / move_rate
    seconds = 2 * dwell + move

    def psi(t):
        return np.where(t < dwell, 0.0, np.where(t < dwell + move, move_rate * (t - dwell), math.pi))

    def psi_rate(t):
        return np.where((t >= dwell) & (t < dwell + move), move_rate, 0.0)

    def body_rate(t):  # the platform's turn about its z, and the Earth's rate seen by the turned body
        turned = rodrigues_many([0, 0, 1], psi(t))
        earth = np.einsum("nji,j->ni", turned, m.T @ w_enu)
        return earth + np.outer(psi_rate(t), [0.0, 0.0, 1.0])

    def body_force(t):
        return np.einsum("nji,j->ni", rodrigues_many([0, 0, 1], psi(t)), m.T @ f_enu)

    gyro, accel = window(rng, seconds, body_rate, body_force, white, bias, accel_sigma * rng.standard_normal(3))
    write_csv(os.path.join(args.out, "indexed_gyro.csv"), "stamp_ns,dt,dx,dy,dz", gyro)
    write_csv(os.path.join(args.out, "indexed_accel.csv"), "stamp_ns,fx,fy,fz", accel)
    records = []
    for k in range(0, int(round(seconds * 100.0)) + 1):
        t = np.array([k / 100.0])
        records.append([int(round((50.0 + t[0]) * 1e9)), psi(t)[0] + 1e-6 * rng.standard_normal(), psi_rate(t)[0]])
    write_csv(os.path.join(args.out, "indexed_indexer.csv"), "stamp_ns,angle,rate", records)
    truth.update({"indexed_heading_deg": heading, "indexed_roll": roll, "indexed_pitch": pitch,
                  "indexed_seconds": seconds})
    with open(os.path.join(args.out, "truth.csv"), "w") as f:
        f.write("key,value\n")
        for key, value in truth.items():
            f.write("%s,%r\n" % (key, float(value)))


if __name__ == "__main__":
    main()
