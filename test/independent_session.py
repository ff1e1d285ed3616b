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

Channel model (the standing wave r = A cos(2 phi - theta) cos(wt + tau) + B sin(2 phi - theta) sin(wt + tau)
seen by the cosine and sine pickoff channels, demodulated against cos(wt) and sin(wt)):
    Ac =  A cos th cos tau - B sin th sin tau      Bc = -A cos th sin tau - B sin th cos tau
    As =  A sin th cos tau + B cos th sin tau      Bs = -A sin th sin tau + B cos th cos tau

Usage: independent_session.py --out BAG --truth YAML [--acceleration 0.5] [--ripple 0.002] [--encoder-noise 2e-6]
       [--encoder-bits 23] [--differenced-rate] [--cos4 0.03] [--cos8 0.003] [--seed 1]
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


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--truth", required=True, help="YAML with the injected K and D")
    parser.add_argument("--rate", type=float, default=0.4, help="plateau rates +-rate, rad/s")
    parser.add_argument("--pairs", type=int, default=6, help="plateau pairs, each sweeping theta by 2 pi")
    parser.add_argument("--acceleration", type=float, default=0.5, help="drive acceleration limit, rad/s^2")
    parser.add_argument("--output-hz", type=float, default=200.0)
    parser.add_argument("--log-hz", type=float, default=100.0, help="turntable log rate")
    parser.add_argument("--cos4", type=float, default=0.03, help="relative cos 4theta term of K")
    parser.add_argument("--cos8", type=float, default=0.003, help="relative cos 8theta term of K")
    parser.add_argument("--ripple", type=float, default=0.0, help="drive ripple, fraction of the rate")
    parser.add_argument("--ripple-hz", type=float, default=0.37)
    parser.add_argument("--encoder-noise", type=float, default=0.0, help="rad, white, on the logged angle")
    parser.add_argument("--encoder-bits", type=int, default=0, help="counts per turn 2^bits; 0: not quantised")
    parser.add_argument("--differenced-rate", action="store_true", help="log the rate as the differenced angle")
    parser.add_argument("--channel-noise", type=float, default=5e-6, help="white noise per channel amplitude")
    parser.add_argument("--seed", type=int, default=1)
    a = parser.parse_args(argv)

    latitude = 0.9
    earth = EARTH_RATE * math.sin(latitude)
    gyro = Gyro(-0.56, [(2, 4e-4, -3e-4), (4, a.cos4, 2e-4), (6, 1e-4, 0.0), (8, a.cos8, -1e-4)],
                1e-5, [(2, 2e-5, -1e-5)])
    amplitude, quadrature, tau = 1.0, 0.02, 0.3
    profile = Profile(acceleration=a.acceleration)
    profile.hold(0.0, 5.0)
    sweep = 2.0 * math.pi / (abs(gyro.k0) * a.rate)
    for _ in range(a.pairs):
        for w in (a.rate, -a.rate):
            profile.hold(w, 3.0 + sweep)
    profile.hold(0.0, 5.0)
    w_ripple = 2.0 * math.pi * a.ripple_hz

    def table_rate(t):
        return profile.rate(t) * (1.0 + a.ripple * math.sin(w_ripple * t))

    def derivative(t, theta):
        table = table_rate(t)
        return gyro.k(theta) * (table + earth) + gyro.d(theta), table

    # RK4 for (theta, table angle) on a step that divides both the output and the log period.
    step = 1.0 / (2.0 * max(a.output_hz, a.log_hz))
    n = int(profile.end / step)
    theta = np.empty(n + 1)
    alpha = np.empty(n + 1)
    rate = np.empty(n + 1)
    th, al = 0.2, 0.0
    for i in range(n + 1):
        t = i * step
        k1, r1 = derivative(t, th)
        theta[i], alpha[i], rate[i] = th, al, r1
        k2, r2 = derivative(t + step / 2, th + step / 2 * k1)
        k3, r3 = derivative(t + step / 2, th + step / 2 * k2)
        k4, r4 = derivative(t + step, th + step * k3)
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
        for j, i in enumerate(lidx):
            m = TurntableState()
            m.header.seq = j
            m.header.stamp = rospy.Time.from_sec(start + times[i])
            m.header.frame_id = "gyro_link"
            m.angle = logged[j]
            if a.differenced_rate:
                m.rate = (logged[j] - logged[j - 1]) * a.log_hz if j > 0 else 0.0
            else:
                m.rate = rate[i]
            bag.write("/turntable/state", m, m.header.stamp)
    truth = {
        "scale_factor": {"mean": gyro.k0, "orders": [o for o, _, _ in gyro.k_terms],
                         "cos": [gyro.k0 * c for _, c, _ in gyro.k_terms],
                         "sin": [gyro.k0 * s for _, _, s in gyro.k_terms]},
        "drift": {"mean": gyro.d0, "orders": [o for o, _, _ in gyro.d_terms],
                  "cos": [c for _, c, _ in gyro.d_terms], "sin": [s for _, _, s in gyro.d_terms]},
        "session_seconds": float(profile.end),
    }
    with open(a.truth, "w") as f:
        yaml.safe_dump(truth, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
