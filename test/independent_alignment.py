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
  rotation), integrated over each sample by ten Simpson panels. (Those panels split the window's
  `seconds` into round(200 seconds) samples, each scaled as 5 ms: 4.99993 ms in the indexed window, whose
  gyro so sees the move up to 1 ms after its stamps and the indexer say. Kept, so that these files stay
  as they were; the moving window below integrates over the stamps' own 5 ms.)
  Each body axis: angle = the integral of its rate + bias t + white noise (sigma per sample); the
  increments are differences of that angle. The accelerometer: R^T M^T f + bias + white noise.

Moving window (--moving NAME), written beside the others, which stay byte for byte as they were:
  The base (the mount, or the indexer's base with its platform) turns about its rest attitude by a small
  rotation D(t) applied in ENU: body -> ENU is B(t) = D(t) M, or D(t) M Rz(psi(t)) on the indexer (the
  plan above; the indexer's angle is read against its own base, so D does not enter it). D = D_lean
  D_knock D_sway D_yaw, each an exact Rodrigues rotation about a fixed ENU axis, several leans, knocks or
  sways composed in the order given. D turns about the sensor's centre: no lever-arm acceleration.
  Gyros, from attitudes rather than from a rate formula, so that they share no sign with the closed form
  above: the body relative to inertial space is Q(t) = Rot(u, Omega t) B(t), u = (0, cos lat, sin lat)
  the Earth's axis in ENU frozen at t = 0 (the local level turns with the Earth); a sample's increment
  is the sum over 40 sub-steps of the rotation vectors of Q(t_k)^T Q(t_k+1) (body axes). That is the
  integral of the inertial rate but for the sub-steps' coning, h tau^2 |w x w'| / 12 a sample (1.6e-11
  rad for a knock of 1e-3 rad on the turning platform, the self-test's worst); then bias dt and white
  noise on the integrated angle, as above.
  Accelerometer: the mean over each 5 ms sample (a delta-velocity over dt, not a point value, by
  Simpson's rule on the sub-steps) of f_body = B^T ((0, 0, g) + a_vib), a_vib the base's acceleration
  in ENU (the Coriolis term of its velocity, ~1e-7 m/s^2, left out). Then its faults, in this order,
  each on the previous one's output: misalignment (its axes are the body's turned by the rotation
  vector rho: it reads Rot(rho)^T f), scale (times 1 + s_i), axis signs, convention (gravity: minus the
  specific force, -g up at rest), bias (drawn, accelerometer_bias_sigma per axis), white noise, and
  quantisation (each record rounded to a multiple of Q, no remainder carried to the next).
  Motions, t from the window's start (the first sample's start), angles in rad, axes ENU (normalised):
    --lean T,SIZE[,DURATION[,AX,AY,AZ]]  turns by SIZE (0.5 - 0.5 cos(pi u)), u = (t - T) / DURATION in
                                         [0, 1], and stays (DURATION 1 s, 0 a step; East); repeatable
    --knock T,SIZE[,AX,AY,AZ]            a lean of SIZE over 0.05 s plus 2 SIZE exp(-s / 0.15 s)
                                         sin(2 pi 8 Hz s), s = t - T >= 0 (East); repeatable
    --sway A,PERIOD[,AX,AY,AZ[,PHASE]]   A sin(2 pi t / PERIOD + PHASE) (East, phase 0); repeatable
    --yaw-jitter RMS[,LOW,HIGH]          about Up: 20 sines of one amplitude (rms RMS in all), frequencies
                                         uniform in [LOW, HIGH] Hz (0.5, 5), phases uniform
    --vibration RMS[,LOW,HIGH]           a_vib (m/s^2), 20 such sines on each ENU axis, rms RMS per axis,
                                         [10, 40] Hz: the accelerometer feels it, the gyros do not
  Window: --moving-seconds S (120), or --moving-indexed (2 --dwell + 2 pi s, the plan above); the mount
  --moving-heading DEG, --moving-pitch P, --moving-roll R, each drawn as the static window's when not
  given. Accelerometer: --accel-convention specific_force|gravity, --accel-axis-signs SX,SY,SZ,
  --accel-scale SX,SY,SZ (0), --accel-misalignment RX,RY,RZ (rad, 0), --accel-quantum Q (m/s^2, 0 none),
  --accel-noise SIGMA (m/s^2 per sample, 2e-3). The gyro bias and white noise are truth.csv's.
  The draws come after all of those above, so that the windows above stay the same: the mount's heading,
  roll and pitch (drawn even when given), then one seed for each of yaw jitter, vibration, gyro noise,
  the accelerometer (bias, then noise) and the indexer, so that one option does not move another's draws.

Files written in --out (CSV, a header line, one record per line, stamps in integer nanoseconds at each
sample's end, the windows starting at 50 s):
  static_gyro.csv, indexed_gyro.csv      stamp_ns,dt,dx,dy,dz        (rad over dt s, body axes)
  static_accel.csv, indexed_accel.csv    stamp_ns,fx,fy,fz           (m/s^2, body axes)
  indexed_indexer.csv                    stamp_ns,angle,rate         (rad, rad/s; 100 Hz)
  truth.csv                              key,value: latitude (rad), static_heading_deg, static_roll,
                                         static_pitch, indexed_heading_deg (the indexer's zero frame),
                                         indexed_roll, indexed_pitch (rad), static_seconds,
                                         indexed_seconds, white_noise (rad), bias_x, bias_y, bias_z (rad/s),
                                         accelerometer_bias_sigma (m/s^2)
  and with --moving:
  moving_gyro.csv, moving_accel.csv      as above, round(200 moving_seconds) records
  moving_indexer.csv                     as above, with --moving-indexed
  truth.csv, appended (numbers only)     moving_seconds (s), moving_indexed (1 or 0); moving_heading_deg,
                                         moving_roll, moving_pitch (rad) of D M (the body, or the indexer's
                                         zero frame) at the last sample's end, its stamp: the base has
                                         moved, and the alignment reports the attitude at the window's end;
                                         moving_start_heading_deg, moving_start_roll, moving_start_pitch of
                                         D M at the first sample's start; moving_lean_total (rad, the norm
                                         of D's rotation vector at the end); moving_rest_heading_deg,
                                         moving_rest_roll, moving_rest_pitch (M); moving_accelerometer_noise
                                         (m/s^2 per sample)
  moving_truth.json                      the label (text, so not in truth.csv), every moving option as
                                         given, the values resolved (defaults, unit axes), the draws (the
                                         mount, the accelerometer's bias, the sines' frequencies and
                                         phases) and the moving truth again

Usage: independent_alignment.py --out DIR [--seed 1] [--latitude 0.9] [--static-seconds 120] [--dwell 60]
           [--moving NAME [moving options]]
       independent_alignment.py --self-test    (checks the moving model against closed forms; no files)
  e.g. --moving lean --lean 30,0.002,1,0,1,0 --lean 70,-0.001; --moving knock --knock 40,5e-4,0,0,1;
  --moving ship --sway 1e-4,8 --sway 5e-5,11,0,1,0,0.5 --yaw-jitter 2e-5; --moving engine --vibration
  0.05,10,40; --moving wrong --accel-convention gravity --accel-axis-signs -1,1,1; --moving table
  --moving-indexed --dwell 60 --knock 20,1e-4. A value that starts with a minus may follow its option as
  it is (--accel-axis-signs -1,1,1). A bad option exits with code 2 and one line that names it.
"""
import argparse
import contextlib
import io
import json
import math
import os
import re
import sys
import time

import numpy as np

OMEGA = 7.2921150e-5
G = 9.80665
RATE_HZ = 200.0
SUBSTEPS = 40  # per gyro sample in the moving window; even, for Simpson's rule on the accelerometer
CHUNK = 2000  # samples per vectorised block, so that the (n, 3, 3) arrays stay small
MOVE_RATE = 0.5  # rad/s, the indexer's move
KNOCK_STEP, KNOCK_AMPLITUDE, KNOCK_HZ, KNOCK_DECAY = 0.05, 2.0, 8.0, 0.15
TONES = 20
MAX_TONE_HZ = 200.0  # 20 sub-steps of the tone's period at least: Simpson's mean stays within 1e-5
EAST, UP = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)


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



def attitude_of(r):
    """(heading_deg, roll, pitch) of a rotation body -> ENU, mount_rotation's inverse: mount_rotation is
    Rz(90 deg - H) Ry(p) Rx(r) (each turn about an axis already turned)."""
    pitch = -math.asin(max(-1.0, min(1.0, r[2, 0])))
    roll = math.atan2(r[2, 1], r[2, 2])
    heading = (90.0 - math.degrees(math.atan2(r[1, 0], r[0, 0]))) % 360.0
    return (0.0 if heading >= 360.0 else heading), roll, pitch


def rotation_vectors(r):
    """Rotation vectors (unit axis times angle, angle below pi) of rotations r, shape (n, 3, 3)."""
    v = 0.5 * np.stack([r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], axis=1)
    s = np.linalg.norm(v, axis=1)  # sin(angle)
    angle = np.arctan2(s, 0.5 * (r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2] - 1.0))
    scale = 1.0 + s * s / 6.0  # angle / sin(angle) near 0
    big = s > 1e-6
    scale[big] = angle[big] / s[big]
    return v * scale[:, None]


def rotation_of_vector(rho):
    """The rotation by the rotation vector rho (identity for rho = 0)."""
    angle = float(np.linalg.norm(rho))
    return np.eye(3) if angle == 0.0 else rodrigues(rho, angle)


def raised(u):
    """0 before, 0.5 - 0.5 cos(pi u) over u in [0, 1], 1 after."""
    return 0.5 - 0.5 * np.cos(math.pi * np.clip(u, 0.0, 1.0))


def sines(t, amplitude, frequencies, phases):
    """sum_i amplitude sin(2 pi f_i t + phase_i) at each of the times t."""
    return amplitude * np.sin(2.0 * math.pi * np.outer(t, frequencies) + phases).sum(axis=1)


class Motion:
    """The base's rotation D(t) (ENU) and its linear acceleration (ENU), from a resolved plan and the
    random draws the plan needs (the sines of yaw jitter and vibration)."""

    def __init__(self, plan, yaw_rng, vibration_rng):
        self.leans, self.knocks, self.sways = plan["lean"], plan["knock"], plan["sway"]
        self.yaw = self.vibration = None
        if plan["yaw_jitter"]:
            rms, low, high = plan["yaw_jitter"]
            self.yaw = (rms * math.sqrt(2.0 / TONES), yaw_rng.uniform(low, high, TONES),
                        yaw_rng.uniform(0.0, 2.0 * math.pi, TONES))
        if plan["vibration"]:
            rms, low, high = plan["vibration"]
            self.vibration = (rms * math.sqrt(2.0 / TONES), vibration_rng.uniform(low, high, (3, TONES)),
                              vibration_rng.uniform(0.0, 2.0 * math.pi, (3, TONES)))

    def draws(self):
        out = {}
        if self.yaw:
            out["yaw_jitter"] = {"amplitude": self.yaw[0], "frequencies_hz": self.yaw[1].tolist(),
                                 "phases": self.yaw[2].tolist()}
        if self.vibration:
            out["vibration"] = {"amplitude": self.vibration[0], "frequencies_hz": self.vibration[1].tolist(),
                                "phases": self.vibration[2].tolist()}
        return out

    def factors(self, t):
        """(axis, angles, rates) at the times t of each rotation of D, in the order D = D_lean D_knock D_sway
        D_yaw (a step's rate, a delta, left out)."""
        for start, size, duration, axis in self.leans:
            if duration == 0.0:
                yield axis, size * np.where(t >= start, 1.0, 0.0), np.zeros(len(t))
            else:
                u = (t - start) / duration
                rate = np.where((u > 0.0) & (u < 1.0), 0.5 * math.pi / duration * np.sin(math.pi * u), 0.0)
                yield axis, size * raised(u), size * rate
        for start, size, axis in self.knocks:
            s = t - start
            u, w = s / KNOCK_STEP, 2.0 * math.pi * KNOCK_HZ
            decay = np.exp(-np.maximum(s, 0.0) / KNOCK_DECAY)
            ring = np.where(s >= 0.0, KNOCK_AMPLITUDE * size * decay * np.sin(w * s), 0.0)
            ring_rate = np.where(s >= 0.0, KNOCK_AMPLITUDE * size * decay * (w * np.cos(w * s) -
                                                                                np.sin(w * s) / KNOCK_DECAY), 0.0)
            step_rate = np.where((u > 0.0) & (u < 1.0), 0.5 * math.pi / KNOCK_STEP * np.sin(math.pi * u), 0.0)
            yield axis, size * raised(u) + ring, size * step_rate + ring_rate
        for amplitude, period, axis, phase in self.sways:
            w = 2.0 * math.pi / period
            yield axis, amplitude * np.sin(w * t + phase), amplitude * w * np.cos(w * t + phase)
        if self.yaw:
            amplitude, frequencies, phases = self.yaw
            rate = (2.0 * math.pi * frequencies * np.cos(2.0 * math.pi * np.outer(t, frequencies) + phases)).sum(axis=1)
            yield UP, sines(t, *self.yaw), amplitude * rate

    def base(self, t):
        """D at each of the times t, shape (n, 3, 3)."""
        d = np.broadcast_to(np.eye(3), (len(t), 3, 3))
        for axis, angles, _ in self.factors(t):
            d = np.matmul(d, rodrigues_many(axis, angles))
        return d

    def rate(self, t):
        """D's angular rate in D's own axes, vee(D^T D') = sum_i P_i^T a_i theta_i' (P_i the factors after
        the i-th), at each of the times t, shape (n, 3): the self-test's reference."""
        out, after = np.zeros((len(t), 3)), np.broadcast_to(np.eye(3), (len(t), 3, 3))
        for axis, angles, rates in reversed(list(self.factors(t))):
            a = np.asarray(axis, float) / np.linalg.norm(axis)
            out += np.einsum("nji,j->ni", after, a) * rates[:, None]
            after = np.matmul(rodrigues_many(axis, angles), after)
        return out

    def acceleration(self, t):
        """The base's linear acceleration in ENU at each of the times t, shape (n, 3)."""
        if not self.vibration:
            return np.zeros((len(t), 3))
        amplitude, frequencies, phases = self.vibration
        return np.stack([sines(t, amplitude, frequencies[i], phases[i]) for i in range(3)], axis=1)


def indexer_angle(t, dwell):
    """The indexer plan of the indexed window: 0 for dwell s, a move at MOVE_RATE to pi, pi."""
    return np.clip(MOVE_RATE * (t - dwell), 0.0, math.pi)


def indexer_rate(t, dwell):
    return np.where((t >= dwell) & (t < dwell + math.pi / MOVE_RATE), MOVE_RATE, 0.0)


def moving_samples(body_to_enu, n, lat, acceleration=None):
    """Noise-free gyro increments and mean specific forces (both (n, 3), body axes) of the n samples of
    5 ms from t = 0, for body_to_enu(times) -> (len, 3, 3) and acceleration(times) -> (len, 3) (ENU).
    Increments: the rotation vectors of Q(t_k)^T Q(t_k+1), Q = Rot(u, Omega t) B(t), summed over the
    SUBSTEPS sub-steps of each sample; forces: Simpson's rule on the same nodes."""
    h = 1.0 / RATE_HZ
    axis = np.array([0.0, math.cos(lat), math.sin(lat)])
    weights = np.where(np.arange(SUBSTEPS) % 2 == 1, 4.0, 2.0)
    weights[0] = 1.0  # and 1 on the sample's last node, the next sample's first
    increments, forces = np.empty((n, 3)), np.empty((n, 3))
    for i0 in range(0, n, CHUNK):
        i1 = min(n, i0 + CHUNK)
        m = i1 - i0
        t = np.arange(i0 * SUBSTEPS, i1 * SUBSTEPS + 1) * (h / SUBSTEPS)
        b = body_to_enu(t)
        q = np.matmul(rodrigues_many(axis, OMEGA * t), b)
        relative = np.matmul(np.swapaxes(q[:-1], 1, 2), q[1:])
        increments[i0:i1] = rotation_vectors(relative).reshape(m, SUBSTEPS, 3).sum(axis=1)
        f_enu = np.array([0.0, 0.0, G]) + (0.0 if acceleration is None else acceleration(t))
        f = np.einsum("nji,nj->ni", b, np.broadcast_to(f_enu, (len(t), 3)))
        forces[i0:i1] = (np.einsum("j,mjk->mk", weights, f[:-1].reshape(m, SUBSTEPS, 3)) +
                         f[SUBSTEPS::SUBSTEPS]) / (3.0 * SUBSTEPS)
    return increments, forces


def accelerometer_faults(forces, plan, bias, rng):
    """The accelerometer's records from the mean specific forces (n, 3, body axes), its faults in the
    module's order: misalignment, scale, axis signs, convention, bias, white noise, quantisation."""
    f = forces @ rotation_of_vector(plan["accel_misalignment"])  # rows: Rot(rho)^T f
    f = f * (1.0 + np.asarray(plan["accel_scale"])) * np.asarray(plan["accel_axis_signs"])
    if plan["accel_convention"] == "gravity":
        f = -f
    f = f + bias + plan["accel_noise"] * rng.standard_normal(f.shape)
    if plan["accel_quantum"] > 0.0:
        f = np.round(f / plan["accel_quantum"]) * plan["accel_quantum"]
    return f


def moving_window(plan, rng, lat, white, bias, accel_sigma):
    """The moving window's records (gyro, accel, indexer or None), its truth and its draws."""
    # The draws: the mount (always, so that giving it changes nothing else), then one seed a stream.
    drawn = rng.uniform(0.0, 360.0), 0.01 * rng.standard_normal(), 0.01 * rng.standard_normal()
    yaw_rng, vibration_rng, gyro_rng, accel_rng, indexer_rng = [
        np.random.default_rng(int(s)) for s in rng.integers(0, 2 ** 62, 5)]
    heading, roll, pitch = [drawn[i] if plan[k] is None else plan[k] for i, k in
                            enumerate(("moving_heading", "moving_roll", "moving_pitch"))]
    m = mount_rotation(heading, pitch, roll)
    motion = Motion(plan, yaw_rng, vibration_rng)
    seconds, dwell, h = plan["moving_seconds"], plan["dwell"], 1.0 / RATE_HZ
    n = int(round(seconds * RATE_HZ))
    if plan["moving_indexed"]:
        def body(t):
            return np.matmul(np.matmul(motion.base(t), m), rodrigues_many(UP, indexer_angle(t, dwell)))
    else:
        def body(t):
            return np.matmul(motion.base(t), m)
    increments, forces = moving_samples(body, n, lat, motion.acceleration)
    deltas = increments + bias * h + white * np.diff(gyro_rng.standard_normal((n + 1, 3)), axis=0)
    accel_bias = accel_sigma * accel_rng.standard_normal(3)
    records = accelerometer_faults(forces, plan, accel_bias, accel_rng)
    stamps = np.round((50.0 + np.arange(1, n + 1) * h) * 1e9).astype(np.int64).tolist()
    gyro = zip(stamps, [h] * n, *deltas.T.tolist())
    accel = zip(stamps, *records.T.tolist())
    indexer = None
    if plan["moving_indexed"]:
        t = np.arange(int(round(seconds * 100.0)) + 1) / 100.0
        angle = indexer_angle(t, dwell) + 1e-6 * indexer_rng.standard_normal(len(t))
        indexer = zip(np.round((50.0 + t) * 1e9).astype(np.int64).tolist(), angle.tolist(),
                      indexer_rate(t, dwell).tolist())
    d_end, d_start = motion.base(np.array([n * h]))[0], motion.base(np.array([0.0]))[0]
    end, start, rest = attitude_of(d_end @ m), attitude_of(d_start @ m), attitude_of(m)
    truth = {"moving_seconds": seconds, "moving_indexed": float(plan["moving_indexed"]),
             "moving_heading_deg": end[0], "moving_roll": end[1], "moving_pitch": end[2],
             "moving_start_heading_deg": start[0], "moving_start_roll": start[1], "moving_start_pitch": start[2],
             "moving_lean_total": float(np.linalg.norm(rotation_vectors(d_end[None])[0])),
             "moving_rest_heading_deg": rest[0], "moving_rest_roll": rest[1], "moving_rest_pitch": rest[2],
             "moving_accelerometer_noise": plan["accel_noise"]}
    draws = dict(mount={"heading_deg": drawn[0], "roll": drawn[1], "pitch": drawn[2]},
                 accelerometer_bias=accel_bias.tolist(), **motion.draws())
    return gyro, accel, indexer, truth, draws


# --- Options ------------------------------------------------------------------------------------------

class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line naming the option, exit code 2 (argparse's usage left out)
        self.exit(2, "%s: error: %s\n" % (self.prog, message.splitlines()[0] if message else "bad option"))


MOVING_OPTIONS = ("--moving-seconds", "--moving-indexed", "--moving-heading", "--moving-pitch", "--moving-roll",
                  "--lean", "--knock", "--sway", "--yaw-jitter", "--vibration", "--accel-convention",
                  "--accel-axis-signs", "--accel-scale", "--accel-misalignment", "--accel-quantum", "--accel-noise")


def make_parser():
    p = Parser(prog="independent_alignment.py", description=__doc__,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--latitude", type=float, default=0.9)
    p.add_argument("--static-seconds", type=float, default=120.0)
    p.add_argument("--dwell", type=float, default=60.0)
    p.add_argument("--self-test", action="store_true")
    p.add_argument("--moving", metavar="NAME")
    p.add_argument("--moving-indexed", action="store_true")
    forms = {"--moving-seconds": "S", "--moving-heading": "DEG", "--moving-pitch": "P", "--moving-roll": "R",
             "--lean": "T,SIZE[,DURATION[,AX,AY,AZ]]", "--knock": "T,SIZE[,AX,AY,AZ]",
             "--sway": "A,PERIOD[,AX,AY,AZ[,PHASE]]", "--yaw-jitter": "RMS[,LOW,HIGH]", "--vibration": "RMS[,LOW,HIGH]",
             "--accel-convention": "specific_force|gravity", "--accel-axis-signs": "SX,SY,SZ",
             "--accel-scale": "SX,SY,SZ", "--accel-misalignment": "RX,RY,RZ", "--accel-quantum": "Q",
             "--accel-noise": "SIGMA"}
    for option, form in forms.items():  # kept as text, as given, for the JSON; resolve() reads them
        repeat = option in ("--lean", "--knock", "--sway", "--yaw-jitter", "--vibration")
        p.add_argument(option, metavar=form, action="append" if repeat else "store")
    return p


def join_negative_values(argv):
    """'--opt -1,1,1' as '--opt=-1,1,1': argparse takes a value that starts with '-' for an option."""
    takes_value = set(MOVING_OPTIONS) - {"--moving-indexed"} | {"--moving", "--out", "--seed", "--latitude",
                                                                 "--static-seconds", "--dwell"}
    out, i = [], 0
    while i < len(argv):
        if argv[i] in takes_value and i + 1 < len(argv) and re.match(r"-[0-9.]", argv[i + 1]):
            out.append(argv[i] + "=" + argv[i + 1])
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def resolve(parser, args):
    """The moving plan (defaults filled, axes unit, values checked), or None without --moving."""
    def fail(option, message):
        parser.error("%s: %s" % (option, message))

    def numbers(option, text, counts, form):
        try:
            values = [float(x) for x in text.split(",")]
        except ValueError:
            fail(option, "%r is not numbers %s" % (text, form))
        if len(values) not in counts:
            fail(option, "%r has %d numbers, not %s" % (text, len(values), form))
        if not all(math.isfinite(v) for v in values):
            fail(option, "%r is not finite" % text)
        return values

    def axis(option, values):
        norm = math.sqrt(sum(v * v for v in values))
        if norm < 1e-12:
            fail(option, "the axis %s has zero length" % ",".join("%g" % v for v in values))
        return tuple(v / norm for v in values)

    def scalar(option, text, low=None, strict=False):
        value = numbers(option, text, (1,), "(one number)")[0]
        if low is not None and (value < low or (strict and value == low)):
            fail(option, "%g is %s %g" % (value, "not above" if strict else "below", low))
        return value

    given = {o: getattr(args, o[2:].replace("-", "_")) for o in MOVING_OPTIONS}
    given = {o: v for o, v in given.items() if v not in (None, False)}
    if args.moving is None:
        if given:
            fail(sorted(given)[0], "needs --moving NAME")
        return None
    plan = {"label": args.moving, "options": given, "dwell": args.dwell, "moving_indexed": args.moving_indexed}
    if args.moving_indexed:
        if args.moving_seconds is not None:
            fail("--moving-seconds", "not with --moving-indexed (its length is 2 --dwell + pi / 0.5 s)")
        if not (math.isfinite(args.dwell) and args.dwell >= 0.0):
            fail("--dwell", "%g is not a length of time" % args.dwell)
        seconds = 2.0 * args.dwell + math.pi / MOVE_RATE
    else:
        seconds = 120.0 if args.moving_seconds is None else scalar("--moving-seconds", args.moving_seconds, 0.0, True)
        if int(round(seconds * RATE_HZ)) < 1:
            fail("--moving-seconds", "%g s holds no 5 ms sample" % seconds)
    plan["moving_seconds"] = seconds
    plan["moving_heading"] = None if args.moving_heading is None else scalar("--moving-heading", args.moving_heading)
    plan["moving_roll"] = None if args.moving_roll is None else scalar("--moving-roll", args.moving_roll)
    plan["moving_pitch"] = None if args.moving_pitch is None else scalar("--moving-pitch", args.moving_pitch)
    if plan["moving_pitch"] is not None and abs(plan["moving_pitch"]) >= math.pi / 2:
        fail("--moving-pitch", "%g rad puts the x axis vertical or beyond" % plan["moving_pitch"])

    def start(option, value):
        if not 0.0 <= value <= seconds:
            fail(option, "T = %g s is outside the window [0, %g] s" % (value, seconds))
        return value

    def size(option, value, limit):
        if abs(value) >= limit:
            fail(option, "SIZE %g rad is not below %g rad" % (value, limit))
        return value

    plan["lean"] = []
    for text in args.lean or []:
        v = numbers("--lean", text, (2, 3, 6), "T,SIZE[,DURATION[,AX,AY,AZ]]")
        duration = v[2] if len(v) > 2 else 1.0
        if duration < 0.0:
            fail("--lean", "DURATION %g s is negative" % duration)
        plan["lean"].append((start("--lean", v[0]), size("--lean", v[1], math.pi), duration,
                             axis("--lean", v[3:6]) if len(v) == 6 else EAST))
    plan["knock"] = []
    for text in args.knock or []:
        v = numbers("--knock", text, (2, 5), "T,SIZE[,AX,AY,AZ]")
        plan["knock"].append((start("--knock", v[0]), size("--knock", v[1], math.pi / (2 * KNOCK_AMPLITUDE)),
                              axis("--knock", v[2:5]) if len(v) == 5 else EAST))
    plan["sway"] = []
    for text in args.sway or []:
        v = numbers("--sway", text, (2, 5, 6), "AMPLITUDE,PERIOD[,AX,AY,AZ[,PHASE]]")
        if v[1] <= 0.0:
            fail("--sway", "PERIOD %g s is not above 0" % v[1])
        plan["sway"].append((size("--sway", v[0], math.pi), v[1], axis("--sway", v[2:5]) if len(v) >= 5 else EAST,
                             v[5] if len(v) == 6 else 0.0))
    for option, key, band in (("--yaw-jitter", "yaw_jitter", (0.5, 5.0)), ("--vibration", "vibration", (10.0, 40.0))):
        texts = getattr(args, key) or []
        if len(texts) > 1:
            fail(option, "given %d times (once at most)" % len(texts))
        plan[key] = None
        if texts:
            v = numbers(option, texts[0], (1, 3), "RMS[,LOW,HIGH]")
            rms, low, high = v[0], *(v[1:] if len(v) == 3 else band)
            if rms < 0.0:
                fail(option, "RMS %g is negative" % rms)
            if not 0.0 <= low <= high <= MAX_TONE_HZ:
                fail(option, "the band [%g, %g] Hz is not within 0 <= LOW <= HIGH <= %g" % (low, high, MAX_TONE_HZ))
            plan[key] = (rms, low, high)
    convention = args.accel_convention or "specific_force"
    if convention not in ("specific_force", "gravity"):
        fail("--accel-convention", "%r is not specific_force or gravity" % convention)
    plan["accel_convention"] = convention
    signs = (1.0, 1.0, 1.0)
    if args.accel_axis_signs is not None:
        signs = tuple(numbers("--accel-axis-signs", args.accel_axis_signs, (3,), "SX,SY,SZ"))
        if any(s not in (-1.0, 1.0) for s in signs):
            fail("--accel-axis-signs", "%r: each sign is 1 or -1" % args.accel_axis_signs)
    plan["accel_axis_signs"] = signs
    scale = (0.0, 0.0, 0.0)
    if args.accel_scale is not None:
        scale = tuple(numbers("--accel-scale", args.accel_scale, (3,), "SX,SY,SZ"))
        if any(s <= -1.0 for s in scale):
            fail("--accel-scale", "%r: a relative scale error of -1 or below leaves no axis" % args.accel_scale)
    plan["accel_scale"] = scale
    plan["accel_misalignment"] = (0.0, 0.0, 0.0) if args.accel_misalignment is None else tuple(
        numbers("--accel-misalignment", args.accel_misalignment, (3,), "RX,RY,RZ"))
    plan["accel_quantum"] = 0.0 if args.accel_quantum is None else scalar("--accel-quantum", args.accel_quantum, 0.0)
    plan["accel_noise"] = 2e-3 if args.accel_noise is None else scalar("--accel-noise", args.accel_noise, 0.0)
    return plan


def parse(argv):
    parser = make_parser()
    args = parser.parse_args(join_negative_values(list(argv)))
    if args.self_test:
        return args, None
    if args.out is None:
        parser.error("--out: required (unless --self-test)")
    return args, resolve(parser, args)


# --- Self-test ----------------------------------------------------------------------------------------

def indexed_closed_form(m, w_enu, dwell, n):
    """The indexed window's closed-form rate psi' z + R(psi)^T M^T W integrated exactly over each sample
    (the sines and cosines of the linear psi integrated in closed form, piece by piece of the plan)."""
    h, v = 1.0 / RATE_HZ, m.T @ w_enu
    a = np.arange(n) * h
    b = a + h
    move = math.pi / MOVE_RATE
    out = np.zeros((n, 3))
    out[:, 2] = v[2] * (b - a)
    for lo, hi, psi0, rate in ((0.0, dwell, 0.0, 0.0), (dwell, dwell + move, 0.0, MOVE_RATE),
                               (dwell + move, np.inf, math.pi, 0.0)):
        t0, t1 = np.clip(a, lo, hi), np.clip(b, lo, hi)
        if rate == 0.0:
            c, s, turn = math.cos(psi0) * (t1 - t0), math.sin(psi0) * (t1 - t0), 0.0
        else:
            p0, p1 = psi0 + rate * (t0 - lo), psi0 + rate * (t1 - lo)
            c, s, turn = (np.sin(p1) - np.sin(p0)) / rate, (np.cos(p0) - np.cos(p1)) / rate, p1 - p0
        out[:, 0] += c * v[0] + s * v[1]
        out[:, 1] += -s * v[0] + c * v[1]
        out[:, 2] += turn
    return out


def integral(f, end, breaks):
    """The integral of f(times) -> (len, 3) over [0, end]: Gauss-Legendre, 8 nodes on each piece of at
    most 0.1 s between the breaks (where f is not smooth)."""
    x, w = np.polynomial.legendre.leggauss(8)
    edges = sorted({0.0, end} | {b for b in breaks if 0.0 < b < end})
    total = np.zeros(3)
    for lo, hi in zip(edges[:-1], edges[1:]):
        cuts = np.linspace(lo, hi, int(math.ceil((hi - lo) / 0.1)) + 1)
        mid, half = 0.5 * (cuts[1:] + cuts[:-1]), 0.5 * (cuts[1:] - cuts[:-1])
        t = (mid[:, None] + half[:, None] * x[None]).ravel()
        total += ((half[:, None] * w[None]).ravel()[:, None] * f(t)).sum(axis=0)
    return total


def per_sample_integral(f, n, breaks):
    """The integral of f(times) -> (len, 3) over each of n samples of 5 ms from 0: Gauss-Legendre, 8
    nodes, a sample split at the breaks inside it (where f jumps)."""
    h = 1.0 / RATE_HZ
    x, w = np.polynomial.legendre.leggauss(8)
    cuts = [[k * h, (k + 1) * h] for k in range(n)]
    for b in breaks:
        k = int(b // h)
        if 0 <= k < n and cuts[k][0] < b < cuts[k][-1]:
            cuts[k] = sorted(cuts[k] + [b])
    index, lo, hi = zip(*[(k, c[j], c[j + 1]) for k, c in enumerate(cuts) for j in range(len(c) - 1)])
    lo, hi = np.array(lo), np.array(hi)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    values = f((mid[:, None] + half[:, None] * x[None]).ravel()).reshape(len(lo), 8, 3)
    out = np.zeros((n, 3))
    np.add.at(out, np.array(index), np.einsum("ij,j,ijk->ik", np.broadcast_to(half[:, None], (len(lo), 8)), w, values))
    return out


def self_test():
    failures = []

    def check(name, ok, detail):
        print("%s %s: %s" % ("ok  " if ok else "FAIL", name, detail))
        if not ok:
            failures.append(name)

    began = time.time()
    lat, h, dwell = 0.9, 1.0 / RATE_HZ, 60.0
    w_enu = OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])
    m = mount_rotation(123.4, 0.004, -0.007)
    worst = max(max(abs(a - b), abs(c - d), abs(e - f) % 360.0) for (e, c, a), (f, d, b) in
                ((attitude_of(mount_rotation(hd, p, r)), (hd, r, p)) for hd in (0.0, 10.0, 200.0, 359.9)
                 for p in (-0.3, 0.0, 0.01) for r in (-0.2, 0.0, 0.02)))
    check("(0) heading/roll/pitch invert mount_rotation", worst < 1e-12, "worst %.1e" % worst)

    # (1) No motion: the attitudes' sub-steps against the closed forms.
    n = int(round(120.0 * RATE_HZ))
    inc, forces = moving_samples(lambda t: np.broadcast_to(m, (len(t), 3, 3)), n, lat)
    err = np.abs(inc - h * (m.T @ w_enu)).max()
    ferr = np.abs(forces - m.T @ np.array([0.0, 0.0, G])).max()
    check("(1) static, 120 s: sub-step increments vs M^T W dt", err < 1e-12,
          "max |difference| %.2e rad per sample (accelerometer %.1e m/s^2)" % (err, ferr))
    seconds = 2.0 * dwell + math.pi / MOVE_RATE
    n = int(round(seconds * RATE_HZ))
    inc, _ = moving_samples(lambda t: np.matmul(m, rodrigues_many(UP, indexer_angle(t, dwell))), n, lat)
    exact = indexed_closed_form(m, w_enu, dwell, n)
    err = np.abs(inc - exact).max()
    check("(1) indexed, %.3f s: sub-step increments vs psi' z + R(psi)^T M^T W integrated exactly" % seconds,
          err < 1e-12, "max |difference| %.2e rad per sample" % err)
    # For the record: the indexed window above (window(), ten Simpson panels on a grid of `seconds` split
    # into round(200 seconds) samples, scaled by 5 ms) against the same exact integral.
    move = math.pi / MOVE_RATE

    def old_rate(t):
        psi = np.where(t < dwell, 0.0, np.where(t < dwell + move, MOVE_RATE * (t - dwell), math.pi))
        rate = np.where((t >= dwell) & (t < dwell + move), MOVE_RATE, 0.0)
        return np.einsum("nji,j->ni", rodrigues_many(UP, psi), m.T @ w_enu) + np.outer(rate, UP)

    old, _ = window(np.random.default_rng(0), seconds, old_rate, lambda t: np.zeros((len(t), 3)), 0.0,
                    np.zeros(3), np.zeros(3))
    old = np.array(old)[:, 2:]
    diff = np.abs(old - exact)
    print("info (1) the indexed_*.csv integration (kept as it is) vs the exact one: max %.2e rad (sample %d), "
          "median %.2e; its z turn sums to pi %+.2e rad (its grid spans %.6f s, the stamps %.6f s)"
          % (diff.max(), int(diff.max(axis=1).argmax()), float(np.median(diff)),
             old[:, 2].sum() - math.pi - n * h * (m.T @ w_enu)[2], seconds, n * h))

    # (2) A lean's increments, noise off: their sum less the Earth's rate integrated (through the turning
    # body) is the lean's rotation, M^T a SIZE in body axes (R(psi)^T M^T a SIZE on the indexer at psi).
    cases = [("static, 60 s, 0.01 rad about East at 30 s over 1 s", 60.0, False, (30.0, 0.01, 1.0, EAST)),
             ("static, 60 s, -0.02 rad about (0.3,-0.5,0.8) at 40.3 s over 0.37 s", 60.0, False,
              (40.3, -0.02, 0.37, tuple(np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])))),
             ("static, 60 s, 0.05 rad step about North at 20.0001 s", 60.0, False, (20.0001, 0.05, 0.0, (0, 1, 0))),
             ("indexed, 0.01 rad about North at 70 s over 1 s (platform at pi)", seconds, True,
              (70.0, 0.01, 1.0, (0.0, 1.0, 0.0)))]
    for name, length, indexed, lean in cases:
        plan = {"lean": [lean], "knock": [], "sway": [], "yaw_jitter": None, "vibration": None}
        motion = Motion(plan, None, None)
        if indexed:
            def body(t):
                return np.matmul(np.matmul(motion.base(t), m), rodrigues_many(UP, indexer_angle(t, dwell)))
        else:
            def body(t):
                return np.matmul(motion.base(t), m)
        n = int(round(length * RATE_HZ))
        inc, _ = moving_samples(body, n, lat)
        breaks = [lean[0], lean[0] + lean[2]] + ([dwell, dwell + move] if indexed else [])
        earth = integral(lambda t: np.einsum("nji,j->ni", body(t), w_enu), n * h, breaks)
        psi0 = math.pi if indexed else 0.0
        expected = rodrigues(UP, psi0).T @ m.T @ np.array(lean[3], float) * lean[1] + (psi0 * np.array(UP))
        err = np.abs(inc.sum(axis=0) - earth - expected).max()
        check("(2) lean, " + name, err < 1e-9, "|sum - Earth - lean| %.2e rad" % err)

    # (2) Every motion at once, about four axes: each sample's increment against the body rate
    # R(psi)^T M^T (D^T W + vee(D^T D')) + psi' z, D's rate from its factors' closed-form rates.
    plan = {"lean": [(1.0, 0.003, 0.5, tuple(np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)))],
            "knock": [(2.0, 0.001, (0.0, 1.0, 0.0))], "sway": [(2e-4, 0.7, (0.0, 0.6, 0.8), 0.3)],
            "yaw_jitter": (1e-4, 0.5, 5.0), "vibration": None}
    motion = Motion(plan, np.random.default_rng(7), None)
    for indexed, short_dwell in ((False, 0.0), (True, 1.0)):
        def angle(t):
            return indexer_angle(t, short_dwell) if indexed else np.zeros(len(t))

        def body(t):
            return np.matmul(np.matmul(motion.base(t), m), rodrigues_many(UP, angle(t)))

        def rate(t):
            d, turned = motion.base(t), rodrigues_many(UP, angle(t))
            inner = np.einsum("nji,j->ni", d, w_enu) + motion.rate(t)  # D's axes
            rates = np.einsum("nji,nj->ni", turned, inner @ m)  # R(psi)^T M^T inner
            return rates + np.outer(indexer_rate(t, short_dwell) if indexed else np.zeros(len(t)), UP)

        n = int(round(6.0 * RATE_HZ))
        inc, _ = moving_samples(body, n, lat)
        breaks = [short_dwell, short_dwell + move] if indexed else []
        err = np.abs(inc - per_sample_integral(rate, n, breaks)).max()
        check("(2) lean, knock, sway and yaw jitter at once, %s, 6 s: per-sample increments vs the body rate"
              % ("indexed (moving 1-7.3 s)" if indexed else "static"), err < 1e-10,
              "max |difference| %.2e rad per sample (the sub-steps' coning, h tau^2 |w x w'| / 12)" % err)

    # (3) The accelerometer's convention and faults, noise off and on.
    n = 2000
    _, forces = moving_samples(lambda t: np.broadcast_to(m, (len(t), 3, 3)), n, lat)
    faults = {"accel_misalignment": (0.0, 0.0, 0.0), "accel_scale": (0.0, 0.0, 0.0),
              "accel_axis_signs": (1.0, 1.0, 1.0), "accel_convention": "specific_force", "accel_noise": 0.0,
              "accel_quantum": 0.0}
    rng = np.random.default_rng(3)
    up = (m @ accelerometer_faults(forces, faults, np.zeros(3), rng).mean(axis=0))[2]
    down = (m @ accelerometer_faults(forces, dict(faults, accel_convention="gravity"), np.zeros(3), rng)
            .mean(axis=0))
    noisy = (m @ accelerometer_faults(forces, dict(faults, accel_convention="gravity", accel_noise=2e-3),
                                      5e-4 * rng.standard_normal(3), rng).mean(axis=0))[2]
    check("(3) convention gravity flips the mean reading to -g up", abs(up - G) < 1e-9 and
          abs(down[2] + G) < 1e-9 and np.abs(down[:2]).max() < 1e-9 and abs(noisy + G) < 3e-3,
          "specific_force %+.9f, gravity %+.9f (noise and bias on: %+.6f) m/s^2 up" % (up, down[2], noisy))
    plan = {"lean": [], "knock": [], "sway": [], "yaw_jitter": None, "vibration": (0.05, 10.0, 40.0)}
    motion = Motion(plan, None, np.random.default_rng(5))
    _, shaken = moving_samples(lambda t: np.broadcast_to(m, (len(t), 3, 3)), n, lat, motion.acceleration)
    amplitude, frequencies, phases = motion.vibration
    a, b, w = np.arange(n)[:, None] * h, np.arange(1, n + 1)[:, None] * h, 2.0 * math.pi * frequencies
    mean = np.stack([(amplitude * (np.cos(w[i] * a + phases[i]) - np.cos(w[i] * b + phases[i])) / (w[i] * h))
                     .sum(axis=1) for i in range(3)], axis=1)
    err = np.abs(shaken - (np.array([0.0, 0.0, G]) + mean) @ m).max()
    rms = np.sqrt(np.mean(motion.acceleration(np.arange(0.0, 10.0, 1e-3)) ** 2, axis=0))
    check("(3) vibration: each record the sample's mean specific force", err < 1e-9,
          "max |record - exact mean| %.1e m/s^2; rms over 10 s %s m/s^2 (0.05 asked)" %
          (err, ",".join("%.4f" % r for r in rms)))
    signs = accelerometer_faults(forces, dict(faults, accel_axis_signs=(-1.0, 1.0, 1.0)), np.zeros(3), rng)
    check("(3) axis signs -1,1,1 reverse x alone", np.array_equal(signs[:, 0], -forces[:, 0]) and
          np.array_equal(signs[:, 1:], forces[:, 1:]), "x %+.6f for %+.6f" % (signs[0, 0], forces[0, 0]))
    q = accelerometer_faults(forces, dict(faults, accel_quantum=0.01), np.zeros(3), rng)
    check("(3) quantum 0.01 rounds every record", np.abs(q / 0.01 - np.round(q / 0.01)).max() < 1e-9 and
          np.abs(q - forces).max() <= 0.005 + 1e-12, "max |change| %.4f m/s^2" % np.abs(q - forces).max())

    # (4) Every option parses and runs; bad ones exit with 2 and one line naming the option.
    every = ["--out", "unused", "--moving", "every option", "--moving-seconds", "4", "--moving-heading", "-30",
             "--moving-pitch", "-0.01", "--moving-roll", "0.02", "--lean", "1,0.001", "--lean", "1.5,-0.002,0.5",
             "--lean", "2,0.001,0.2,0,1,1", "--knock", "0.5,0.0005", "--knock", "2.5,-0.0005,0,0,1",
             "--sway", "1e-4,2", "--sway", "-1e-4,0.5,0,1,0", "--sway", "2e-4,3,1,1,0,0.7",
             "--yaw-jitter", "1e-4,1,6", "--vibration", "0.05,12,30", "--accel-convention", "gravity",
             "--accel-axis-signs", "-1,1,-1", "--accel-scale", "1e-3,-2e-3,5e-4", "--accel-misalignment",
             "1e-3,-1e-3,2e-3", "--accel-quantum", "1e-4", "--accel-noise", "1e-3"]
    indexed = [a for a in every if a not in ("--moving-seconds", "4")] + ["--moving-indexed", "--dwell", "2"]
    for argv in (every, indexed):
        args, plan = parse(argv)
        gyro, accel, indexer, truth, _ = moving_window(plan, np.random.default_rng(1), lat, 8.75e-6,
                                                       np.zeros(3), 5e-4)
        rows = len(list(gyro)), len(list(accel)), (len(list(indexer)) if indexer else 0)
        check("(4) every option parses and runs%s" % (", indexed" if plan["moving_indexed"] else ""),
              rows[0] == rows[1] == int(round(plan["moving_seconds"] * RATE_HZ)) and
              all(math.isfinite(v) for v in truth.values()),
              "%d gyro, %d accel, %d indexer records; heading %.4f deg at the end, lean total %.2e rad"
              % (rows + (truth["moving_heading_deg"], truth["moving_lean_total"])))
    base = ["--out", "unused", "--moving", "x"]
    bad = [("--lean", base + ["--lean", "1,0.01,-1"]), ("--lean", base + ["--lean", "1,0.01,1,0,0,0"]),
           ("--accel-convention", base + ["--accel-convention", "down"]), ("--lean", base + ["--lean", "1"]),
           ("--lean", base + ["--lean", "1,x"]), ("--lean", base + ["--lean", "500,0.01"]),
           ("--lean", ["--out", "unused", "--lean", "1,0.01"]), ("--knock", base + ["--knock", "1,0.01,0,0,0"]),
           ("--knock", base + ["--knock", "-1,0.01"]), ("--sway", base + ["--sway", "1e-4,0"]),
           ("--sway", base + ["--sway", "1e-4,-5,0,0,1"]), ("--sway", base + ["--sway", "1e-4,5,0,0,0"]),
           ("--yaw-jitter", base + ["--yaw-jitter", "1e-4,5,1"]), ("--yaw-jitter", base + ["--yaw-jitter", "-1"]),
           ("--yaw-jitter", base + ["--yaw-jitter", "1e-4", "--yaw-jitter", "1e-4"]),
           ("--vibration", base + ["--vibration", "0.1,10,500"]), ("--vibration", base + ["--vibration", "nan"]),
           ("--accel-axis-signs", base + ["--accel-axis-signs", "-1,2,1"]),
           ("--accel-axis-signs", base + ["--accel-axis-signs", "-1,1"]),
           ("--accel-scale", base + ["--accel-scale", "0,-1,0"]),
           ("--accel-misalignment", base + ["--accel-misalignment", "0,inf,0"]),
           ("--accel-quantum", base + ["--accel-quantum", "-1e-3"]), ("--accel-noise", base + ["--accel-noise", "x"]),
           ("--moving-seconds", base + ["--moving-seconds", "0"]),
           ("--moving-seconds", base + ["--moving-indexed", "--moving-seconds", "100"]),
           ("--moving-pitch", base + ["--moving-pitch", "2"]), ("--moving-heading", base + ["--moving-heading", "n"]),
           ("--dwell", base + ["--moving-indexed", "--dwell", "-1"]), ("--out", ["--moving", "x"]),
           ("--seed", base + ["--seed", "1.5"]), ("--unknown", base + ["--unknown", "1"])]
    for option, argv in bad:
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            try:
                parse(argv)
                code = 0
            except SystemExit as e:
                code = e.code
        lines = stderr.getvalue().splitlines()
        check("(4) bad %s" % " ".join(argv[4:] if argv[:4] == base else argv),
              code == 2 and len(lines) == 1 and option in lines[0],
              "exit %s: %s" % (code, " | ".join(lines)))

    # (5) The truth's frames: a lean of 0.01 rad about Up, East and North of a level mount heading North.
    for axis, key, expected in ((UP, "moving_heading_deg", 360.0 - math.degrees(0.01)),
                                (EAST, "moving_pitch", -0.01), ((0.0, 1.0, 0.0), "moving_roll", 0.01)):
        _, plan = parse(["--out", "unused", "--moving", "frames", "--moving-seconds", "3", "--moving-heading", "0",
                         "--moving-pitch", "0", "--moving-roll", "0", "--lean", "1,0.01,1,%g,%g,%g" % axis])
        truth = moving_window(plan, np.random.default_rng(1), lat, 0.0, np.zeros(3), 0.0)[3]
        got = truth[key]
        check("(5) a lean of +0.01 rad about (%g,%g,%g): %s" % (axis + (key,)),
              abs(got - expected) < 1e-12 and abs(truth["moving_lean_total"] - 0.01) < 1e-15 and
              min(truth["moving_start_heading_deg"], 360.0 - truth["moving_start_heading_deg"]) < 1e-9,
              "%.12f (expected %.12f), start heading %g" % (got, expected, truth["moving_start_heading_deg"]))
    _, plan = parse(["--out", "unused", "--moving", "knock", "--moving-seconds", "5", "--knock", "1,0.001"])
    truth = moving_window(plan, np.random.default_rng(1), lat, 0.0, np.zeros(3), 0.0)[3]
    check("(5) a knock of 0.001 rad at 1 s leaves the base turned by 0.001 rad at 5 s",
          abs(truth["moving_lean_total"] - 0.001) < 1e-12, "lean total %.15f rad" % truth["moving_lean_total"])
    print("%s: %d check(s) failed, %.1f s" % ("FAILED" if failures else "passed", len(failures), time.time() - began)
          if failures else "passed: every check, %.1f s" % (time.time() - began))
    return 1 if failures else 0


def main():
    args, plan = parse(sys.argv[1:])
    if args.self_test:
        sys.exit(self_test())
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

    # Moving: drawn after everything above, so that the windows above stay as they were.
    if plan is not None:
        gyro, accel, indexer, moving_truth, draws = moving_window(plan, rng, lat, white, bias, accel_sigma)
        write_csv(os.path.join(args.out, "moving_gyro.csv"), "stamp_ns,dt,dx,dy,dz", gyro)
        write_csv(os.path.join(args.out, "moving_accel.csv"), "stamp_ns,fx,fy,fz", accel)
        if indexer is not None:
            write_csv(os.path.join(args.out, "moving_indexer.csv"), "stamp_ns,angle,rate", indexer)
        truth.update(moving_truth)
        resolved = {k: v for k, v in plan.items() if k not in ("label", "options")}
        resolved["lean"] = [dict(zip(("t", "size", "duration", "axis"), v)) for v in plan["lean"]]
        resolved["knock"] = [dict(zip(("t", "size", "axis"), v)) for v in plan["knock"]]
        resolved["sway"] = [dict(zip(("amplitude", "period", "axis", "phase"), v)) for v in plan["sway"]]
        for key in ("yaw_jitter", "vibration"):
            resolved[key] = plan[key] and dict(zip(("rms", "low_hz", "high_hz"), plan[key]))
        with open(os.path.join(args.out, "moving_truth.json"), "w") as f:
            json.dump({"label": plan["label"], "options": plan["options"], "seed": args.seed, "latitude": lat,
                       "resolved": resolved, "draws": draws, "truth": moving_truth}, f, indent=1, sort_keys=False)
            f.write("\n")
    with open(os.path.join(args.out, "truth.csv"), "w") as f:
        f.write("key,value\n")
        for key, value in truth.items():
            f.write("%s,%r\n" % (key, float(value)))


if __name__ == "__main__":
    main()
