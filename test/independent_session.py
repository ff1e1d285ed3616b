#!/usr/bin/env python3
"""An independent generator of dual-rate turntable sessions, written without the package's simulator
so that simulator and calibrator cannot share one mistake. It integrates

    d theta/dt = K(theta) (Omega_table(t) + Omega_E) + D(theta)

by RK4 with a chosen harmonic K and D, where the table rate follows a dual-rate profile (ramps at a
fixed acceleration) times 1 + a sin(2 pi f t) (drive ripple), forms the four channel amplitudes of an
ideal pickoff for a wave of amplitude A, quadrature B and phase tau at angle theta, adds white noise,
and logs the table as a controller would: the angle read through an encoder (white noise,
quantisation to counts) at its own log rate, the rate either the drive's or the logged angle
differenced at that rate. It writes a bag with /channels (hrg_gyro/ChannelAmplitudes) and
/turntable/state (hrg_gyro/TurntableState), no truth, and the injected K and D as YAML.

Optionally the bias wanders, D0(t) = D0 + R t + W B(t) (t from the session start, B a standard
Wiener process): the trend is inside the RK4 stages; the walk is drawn exactly at the RK4 grid, and
over each step the equation sees a constant, the mean of W B over that step drawn jointly with its
increment (given the increment dB, the mean of B over a step h is B0 + dB / 2 + sqrt(h / 12) N(0, 1)),
so theta receives the walk's exact integral. The plateaus may come in the balanced (Thue-Morse) order
+ - - + - + + -, a repeated rate held through the time a reversal takes. The table controller may
stamp on its own clock: stamp = start + t + offset + rate_error t + (steps at or before t) + jitter
N(0, 1), t the true time of the record, which is still written to the bag at t. TurntableState
header.seq is the controller's record count (0, 1, 2, ...: this controller loses nothing).
Every option left at its default leaves the bag and the truth file as they were before it existed.

Channel model (the standing wave r = A cos(2 phi - theta) cos(wt + tau) + B sin(2 phi - theta) sin(wt + tau)
seen by the cosine and sine pickoff channels, demodulated against cos(wt) and sin(wt)):
    Ac =  A cos th cos tau - B sin th sin tau      Bc = -A cos th sin tau - B sin th cos tau
    As =  A sin th cos tau + B cos th sin tau      Bs = -A sin th sin tau + B cos th cos tau

Usage: independent_session.py --out BAG --truth YAML [--acceleration 0.5] [--ripple 0.002] [--encoder-noise 2e-6]
       [--encoder-bits 23] [--differenced-rate] [--cos4 0.03] [--cos8 0.003] [--seed 1]
       [--bias-trend 5e-10] [--bias-random-walk 2e-8] [--order balanced] [--table-log-rate 100]
       [--table-clock-offset 0.1] [--table-clock-jitter 0.002] [--table-clock-rate-error 2e-6]
       [--table-clock-step AT SIZE ...]
"""
import argparse
import math
import sys

import numpy as np
import rosbag
import rospy
import yaml
from hrg_gyro.msg import ChannelAmplitudes, TurntableState

EARTH_RATE = 7.2921150e-5  # rad/s


class Gyro:
    """K(theta) = K0 (1 + sum_k c_k cos k theta + s_k sin k theta), D(theta) = D0 + sum ..., all even k."""

    def __init__(self, k0, k_terms, d0, d_terms):
        self.k0, self.k_terms, self.d0, self.d_terms = k0, k_terms, d0, d_terms

    def k(self, theta):
        v = 1.0
        for order, c, s in self.k_terms:
            v += c * math.cos(order * theta) + s * math.sin(order * theta)
        return self.k0 * v

    def d(self, theta):
        v = self.d0
        for order, c, s in self.d_terms:
            v += c * math.cos(order * theta) + s * math.sin(order * theta)
        return v


class Profile:
    """Commanded table rate: piecewise linear (holds and constant-acceleration ramps)."""

    def __init__(self, acceleration):
        self.acceleration = acceleration
        self.pieces = []  # (start, duration, rate0, accel)
        self.end = 0.0

    def _append(self, duration, rate0, accel):
        self.pieces.append((self.end, duration, rate0, accel))
        self.end += duration

    def final_rate(self):
        if not self.pieces:
            return 0.0
        start, duration, rate0, accel = self.pieces[-1]
        return rate0 + accel * duration

    def hold(self, rate, duration):
        now = self.final_rate()
        if now != rate:
            a = math.copysign(self.acceleration, rate - now)
            self._append((rate - now) / a, now, a)
        self._append(duration, rate, 0.0)

    def rate(self, t):
        for start, duration, rate0, accel in self.pieces:
            if t < start + duration:
                return rate0 + accel * max(0.0, t - start)
        return 0.0


def thue_morse(n):
    """0 1 1 0 1 0 0 1 ...: the parity of the number of ones in n."""
    return bin(n).count("1") % 2


def plateau_signs(pairs, order):
    """+1 / -1 for each of the 2 x pairs plateaus."""
    if order == "balanced":
        return [1 - 2 * thue_morse(n) for n in range(2 * pairs)]
    return [1 - 2 * (n % 2) for n in range(2 * pairs)]


def wiener_on_grid(n, step, rng):
    """B at the n + 1 grid points (B(0) = 0) and the mean of B over each of the n steps, drawn jointly."""
    increments = math.sqrt(step) * rng.standard_normal(n)
    b = np.concatenate(([0.0], np.cumsum(increments)))
    means = b[:-1] + 0.5 * increments + math.sqrt(step / 12.0) * rng.standard_normal(n)
    return b, means


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--truth", required=True, help="YAML with the injected K and D")
    parser.add_argument("--rate", type=float, default=0.4, help="plateau rates +-rate, rad/s")
    parser.add_argument("--pairs", type=int, default=6, help="plateau pairs, each sweeping theta by 2 pi")
    parser.add_argument("--acceleration", type=float, default=0.5, help="drive acceleration limit, rad/s^2")
    parser.add_argument("--output-hz", type=float, default=200.0)
    parser.add_argument("--log-hz", "--table-log-rate", dest="log_hz", type=float, default=100.0,
                        help="turntable log rate, Hz (the table's own; a whole number of integration steps apart)")
    parser.add_argument("--cos4", type=float, default=0.03, help="relative cos 4theta term of K")
    parser.add_argument("--cos8", type=float, default=0.003, help="relative cos 8theta term of K")
    parser.add_argument("--ripple", type=float, default=0.0, help="drive ripple, fraction of the rate")
    parser.add_argument("--ripple-hz", type=float, default=0.37)
    parser.add_argument("--encoder-noise", type=float, default=0.0, help="rad, white, on the logged angle")
    parser.add_argument("--encoder-bits", type=int, default=0, help="counts per turn 2^bits; 0: not quantised")
    parser.add_argument("--differenced-rate", action="store_true", help="log the rate as the differenced angle")
    parser.add_argument("--channel-noise", type=float, default=5e-6, help="white noise per channel amplitude")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--bias-trend", type=float, default=0.0,
                        help="linear trend of the bias D0, rad/s per s from the session start")
    parser.add_argument("--bias-random-walk", type=float, default=0.0,
                        help="random walk of the bias D0, rad/s/sqrt(s)")
    parser.add_argument("--order", choices=("alternating", "balanced"), default="alternating",
                        help="plateau order: + - + - ... or the Thue-Morse + - - + - + + - ...")
    parser.add_argument("--table-clock-offset", type=float, default=0.0,
                        help="the table controller's clock minus the gyro's, s")
    parser.add_argument("--table-clock-jitter", type=float, default=0.0,
                        help="white jitter of the controller's stamps, s (standard deviation)")
    parser.add_argument("--table-clock-rate-error", type=float, default=0.0,
                        help="the controller's clock runs 1 + this times as fast, s per s")
    parser.add_argument("--table-clock-step", type=float, nargs=2, action="append", default=[],
                        metavar=("AT", "SIZE"),
                        help="the controller's clock jumps by SIZE s from true time AT s on (repeatable)")
    a = parser.parse_args(argv)
    if not (math.isfinite(a.bias_trend) and math.isfinite(a.bias_random_walk) and a.bias_random_walk >= 0.0):
        parser.error("--bias-trend must be finite, --bias-random-walk finite and >= 0")
    if not (math.isfinite(a.table_clock_offset) and math.isfinite(a.table_clock_jitter) and a.table_clock_jitter >= 0.0
            and abs(a.table_clock_rate_error) < 1.0):
        parser.error("--table-clock-offset must be finite, --table-clock-jitter >= 0, "
                     "--table-clock-rate-error in (-1, 1)")
    if any(not (math.isfinite(at) and at >= 0.0 and math.isfinite(size)) for at, size in a.table_clock_step):
        parser.error("--table-clock-step AT SIZE: AT >= 0 s, SIZE finite (s)")
    drifting = a.bias_trend != 0.0 or a.bias_random_walk != 0.0
    clocked = (a.table_clock_offset != 0.0 or a.table_clock_jitter != 0.0 or a.table_clock_rate_error != 0.0
               or bool(a.table_clock_step))

    latitude = 0.9
    earth = EARTH_RATE * math.sin(latitude)
    gyro = Gyro(-0.56, [(2, 4e-4, -3e-4), (4, a.cos4, 2e-4), (6, 1e-4, 0.0), (8, a.cos8, -1e-4)],
                1e-5, [(2, 2e-5, -1e-5)])
    amplitude, quadrature, tau = 1.0, 0.02, 0.3
    profile = Profile(acceleration=a.acceleration)
    profile.hold(0.0, 5.0)
    sweep = 2.0 * math.pi / (abs(gyro.k0) * a.rate)
    reversal = 2.0 * a.rate / a.acceleration  # s from +rate to -rate
    previous = 0
    for sign in plateau_signs(a.pairs, a.order):
        # A repeated rate is held through a reversal's time, so the plateaus stay evenly spaced.
        profile.hold(sign * a.rate, (reversal if sign == previous else 0.0) + 3.0 + sweep)
        previous = sign
    profile.hold(0.0, 5.0)
    w_ripple = 2.0 * math.pi * a.ripple_hz

    def table_rate(t):
        return profile.rate(t) * (1.0 + a.ripple * math.sin(w_ripple * t))

    def derivative(t, theta, walk=0.0):
        table = table_rate(t)
        if drifting:
            return gyro.k(theta) * (table + earth) + gyro.d(theta) + a.bias_trend * t + walk, table
        return gyro.k(theta) * (table + earth) + gyro.d(theta), table

    # RK4 for (theta, table angle) on a step that divides both the output and the log period.
    step = 1.0 / (2.0 * max(a.output_hz, a.log_hz))
    for hz in (a.output_hz, a.log_hz):
        if abs(1.0 / (hz * step) - round(1.0 / (hz * step))) > 1e-9:
            parser.error("a rate of %g Hz is not a whole number of %g s integration steps apart" % (hz, step))
    n = int(profile.end / step)
    # The bias random walk (rad/s) at the grid points and its mean over each step, from its own stream.
    walk_at, walk_mean = np.zeros(n + 2), np.zeros(n + 1)
    if a.bias_random_walk > 0.0:
        b, b_mean = wiener_on_grid(n + 1, step, np.random.default_rng([a.seed, 1]))
        walk_at, walk_mean = a.bias_random_walk * b, a.bias_random_walk * b_mean
    theta = np.empty(n + 1)
    alpha = np.empty(n + 1)
    rate = np.empty(n + 1)
    th, al = 0.2, 0.0
    for i in range(n + 1):
        t = i * step
        w = walk_mean[i]
        k1, r1 = derivative(t, th, w)
        theta[i], alpha[i], rate[i] = th, al, r1
        k2, r2 = derivative(t + step / 2, th + step / 2 * k1, w)
        k3, r3 = derivative(t + step / 2, th + step / 2 * k2, w)
        k4, r4 = derivative(t + step, th + step * k3, w)
        th += step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        al += step / 6 * (r1 + 2 * r2 + 2 * r3 + r4)
    times = np.arange(n + 1) * step

    rng = np.random.default_rng(a.seed)
    start = 1.0  # s: ROS time 0 means unset
    out_every = int(round(1.0 / (a.output_hz * step)))
    log_every = int(round(1.0 / (a.log_hz * step)))
    count = 2 ** a.encoder_bits if a.encoder_bits > 0 else 0
    with rosbag.Bag(a.out, "w") as bag:
        idx = np.arange(0, n + 1, out_every)
        th = theta[idx]
        noise = a.channel_noise * rng.standard_normal((len(idx), 4))
        ct, st, ctau, stau = np.cos(th), np.sin(th), math.cos(tau), math.sin(tau)
        ac = amplitude * ct * ctau - quadrature * st * stau + noise[:, 0]
        bc = -amplitude * ct * stau - quadrature * st * ctau + noise[:, 1]
        as_ = amplitude * st * ctau + quadrature * ct * stau + noise[:, 2]
        bs = -amplitude * st * stau + quadrature * ct * ctau + noise[:, 3]
        for j, i in enumerate(idx):
            m = ChannelAmplitudes()
            m.header.seq = j
            m.header.stamp = rospy.Time.from_sec(start + times[i])
            m.header.frame_id = "gyro_link"
            m.c_in, m.c_quad, m.s_in, m.s_quad = ac[j], bc[j], as_[j], bs[j]
            m.frequency, m.temperature, m.periods = 5000.0, float("nan"), 25
            bag.write("/channels", m, m.header.stamp)
        lidx = np.arange(0, n + 1, log_every)
        logged = alpha[lidx] + a.encoder_noise * rng.standard_normal(len(lidx))
        if count:
            resolution = 2.0 * math.pi / count
            logged = resolution * np.round(logged / resolution)
        stamps = start + times[lidx]
        if clocked:
            t_true = times[lidx]
            error = a.table_clock_offset + a.table_clock_rate_error * t_true
            for at, size in a.table_clock_step:
                error = error + np.where(t_true >= at, size, 0.0)
            jitter_rng = np.random.default_rng([a.seed, 2])
            error = error + a.table_clock_jitter * jitter_rng.standard_normal(len(lidx))
            stamps = np.maximum(stamps + error, 1e-9)  # ROS time 0 means unset
        for j, i in enumerate(lidx):
            m = TurntableState()
            m.header.seq = j  # the controller's record count
            m.header.stamp = rospy.Time.from_sec(stamps[j])
            m.header.frame_id = "gyro_link"
            m.angle = logged[j]
            if a.differenced_rate:
                m.rate = (logged[j] - logged[j - 1]) * a.log_hz if j > 0 else 0.0
            else:
                m.rate = rate[i]
            # Written at the record's true time, whatever the controller's clock says.
            bag.write("/turntable/state", m, rospy.Time.from_sec(start + times[i]))
    truth = {
        "scale_factor": {"mean": gyro.k0, "orders": [o for o, _, _ in gyro.k_terms],
                         "cos": [gyro.k0 * c for _, c, _ in gyro.k_terms],
                         "sin": [gyro.k0 * s for _, _, s in gyro.k_terms]},
        "drift": {"mean": gyro.d0, "orders": [o for o, _, _ in gyro.d_terms],
                  "cos": [c for _, c, _ in gyro.d_terms], "sin": [s for _, _, s in gyro.d_terms]},
        "session_seconds": float(profile.end),
    }
    if a.order != "alternating":
        truth["plateau_order"] = a.order
    if drifting:
        # D0(t) realised at the session's start, middle and end (the walk at the nearest grid point).
        points = [0.0, 0.5 * profile.end, profile.end]
        truth["bias_drift"] = {
            "rate": a.bias_trend, "random_walk": a.bias_random_walk,
            "realised": [[float(t), float(gyro.d0 + a.bias_trend * t + walk_at[min(int(round(t / step)), n + 1)])]
                         for t in points]}
    if clocked:
        truth["table_clock"] = {"log_rate": a.log_hz, "offset": a.table_clock_offset,
                                "jitter": a.table_clock_jitter, "rate_error": a.table_clock_rate_error,
                                "steps": [[at, size] for at, size in a.table_clock_step]}
    with open(a.truth, "w") as f:
        yaml.safe_dump(truth, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
