#!/usr/bin/env python3
"""Simulator-independent check of the calibration: sessions made by test/independent_session.py (its
own dynamics, channel model and table log, no truth topic) are calibrated by `hrg_bag calibrate` with
the nominal prior, and the fitted K is compared with the injected one: the peak over theta of
|K_fit - K_injected - (K0_fit - K0_injected)| and the K0 error, both <= 1 ppm of |K0|.

Cases: the shipped gyro's magnitudes with an encoder-logged angle, a slow drive (40 s ramps), a
strong nonlinearity (3 % cos 4theta, 0.3 % cos 8theta) and a real table log (strong nonlinearity,
0.2 % drive ripple, the rate logged as the differenced encoder angle), a bias that wanders (its trend
found) and a table logged on its own clock (its offset and jitter found). One more reads back what the
generator's options for a wandering bias, the plateau order and the table's clock write."""
import math
import os
import shutil
import subprocess
import sys
import unittest

import rosbag
import rospy
import rostest
import yaml

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
GENERATOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "independent_session.py")


def model(section):
    """K(theta) of a parameter-file style section (mean, orders, cos, sin)."""
    terms = list(zip(section["orders"], section["cos"], section["sin"]))
    return lambda th: section["mean"] + sum(c * math.cos(k * th) + s * math.sin(k * th) for k, c, s in terms)


class IndependentSession(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "independent_session")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.params = os.path.join(rospy.get_param("~package_dir"), "config", "params_uncalibrated.yaml")

    def calibrate(self, name, *generator_args):
        """Generates the session and calibrates it; returns (residual nonlinearity, K0 error), ppm of |K0|.
        The calibration report and the generator's truth are kept in self.report and self.truth."""
        bag, truth = os.path.join(self.work, name + ".bag"), os.path.join(self.work, name + ".truth.yaml")
        out, report = os.path.join(self.work, name + ".yaml"), os.path.join(self.work, name + ".report.yaml")
        subprocess.run([sys.executable, GENERATOR, "--out", bag, "--truth", truth] + list(generator_args),
                       check=True, timeout=600)
        p = subprocess.run([HRG_BAG, "calibrate", bag, "--method", "dual_rate", "--params", self.params,
                            "--out", out, "--report", report], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=600)
        if os.path.exists(report):
            with open(report) as f:
                self.report = yaml.safe_load(f)
        with open(truth) as f:
            self.truth = yaml.safe_load(f)
        if p.returncode != 0:
            why = [line for line in (p.stdout + p.stderr).splitlines() if "REFUSED" in line or "error" in line.lower()]
            print("[ measured ] %s: refused (exit %d): %s" % (name, p.returncode, "; ".join(why)))
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(truth) as f:
            injected = yaml.safe_load(f)["scale_factor"]
        with open(out) as f:
            fitted = yaml.safe_load(f)["scale_factor"]
        k_true, k_fit = model(injected), model(fitted)
        k0 = abs(injected["mean"])
        offset = fitted["mean"] - injected["mean"]
        peak = max(abs(k_fit(th) - k_true(th) - offset) for th in (math.pi * i / 2048 for i in range(2048)))
        residual, k0_error = 1e6 * peak / k0, 1e6 * offset / k0
        print("[ measured ] %s: residual nonlinearity %.3f ppm of |K0|, K0 error %.3f ppm (injected cos 4theta %g, "
              "cos 8theta %g of K0)" % (name, residual, k0_error, injected["cos"][1] / injected["mean"],
                                         injected["cos"][3] / injected["mean"]))
        return residual, k0_error

    def test_moderate_nonlinearity_encoder_angle(self):
        # The shipped gyro's magnitudes (0.2 % cos 4theta), the table angle through a 23-bit encoder
        # with 2 urad of noise at 100 Hz, the drive's rate logged.
        residual, k0_error = self.calibrate("moderate", "--cos4", "2e-3", "--cos8", "0", "--encoder-noise", "2e-6",
                                            "--encoder-bits", "23")
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)

    def test_slow_drive(self):
        # As the moderate case with a drive limited to 0.02 rad/s^2 (40 s ramps).
        residual, k0_error = self.calibrate("slow_drive", "--cos4", "2e-3", "--cos8", "0", "--encoder-noise", "2e-6",
                                            "--encoder-bits", "23", "--acceleration", "0.02")
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)

    def test_strong_nonlinearity(self):
        # 3 % cos 4theta and 0.3 % cos 8theta in K, logs as above.
        residual, k0_error = self.calibrate("strong", "--cos4", "0.03", "--cos8", "0.003", "--encoder-noise", "2e-6",
                                            "--encoder-bits", "23")
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)

    def test_real_table_log(self):
        # Strong nonlinearity, 0.2 % drive ripple at 0.37 Hz, the rate logged as the encoder angle
        # differenced at 100 Hz.
        residual, k0_error = self.calibrate("real_log", "--cos4", "0.03", "--cos8", "0.003", "--ripple", "0.002",
                                            "--encoder-noise", "2e-6", "--encoder-bits", "23", "--differenced-rate")
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)

    def test_a_bias_that_wanders(self):
        # D0 moving by 1e-6 rad/s over the session (about 400 s), plateaus in the alternating order: the
        # calibration fits the trend with K, and finds the injected one.
        residual, k0_error = self.calibrate("wandering_bias", "--cos4", "2e-3", "--cos8", "0", "--encoder-noise",
                                            "2e-6", "--encoder-bits", "23", "--bias-trend", "2.5e-9")
        trend = self.report["bias_trend"]
        print("[ measured ] wandering bias: trend %.4g +- %.2g rad/s per s (injected %.4g)"
              % (trend["coefficients"][0], trend["coefficients_std"][0], self.truth["bias_drift"]["rate"]))
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)
        self.assertAlmostEqual(trend["coefficients"][0], 2.5e-9, delta=3 * trend["coefficients_std"][0])

    def test_the_table_on_its_own_clock(self):
        # The table logged at 100 Hz on a clock 100 ms late with 2 ms of jitter: the stamps regularised,
        # the offset measured at the changes of rate, K within 1 ppm.
        residual, k0_error = self.calibrate("own_clock", "--cos4", "2e-3", "--cos8", "0", "--encoder-noise", "2e-6",
                                            "--encoder-bits", "23", "--table-log-rate", "100",
                                            "--table-clock-offset", "0.1", "--table-clock-jitter", "0.002")
        clock = self.report["table_clock"]
        print("[ measured ] own clock: offset %.4f +- %.4f ms, jitter %.3f ms, regularised %s"
              % (1e3 * clock["offset"], 1e3 * clock["offset_std"], 1e3 * clock["jitter"], clock["regularised"]))
        self.assertLessEqual(residual, 1.0)
        self.assertLessEqual(abs(k0_error), 1.0)
        self.assertTrue(clock["regularised"])
        self.assertAlmostEqual(clock["offset"], 0.1, delta=3 * clock["offset_std"] + 2e-5)
        self.assertAlmostEqual(clock["jitter"], 0.002, delta=0.0002)

    def test_generator_table_clock_plateau_order_and_bias_drift(self):
        # What the generator's own options write, read back from its bag and truth (no calibration):
        # the table at 50 Hz on a clock 0.05 s ahead with 1 ms of jitter and two steps, header.seq the
        # record count, the balanced order over 2 pairs (+ - - +: the two - plateaus one run), the drift's
        # parameters and its realisation in the truth.
        bag_path = os.path.join(self.work, "options.bag")
        truth_path = os.path.join(self.work, "options.truth.yaml")
        subprocess.run([sys.executable, GENERATOR, "--out", bag_path, "--truth", truth_path, "--pairs", "2",
                        "--order", "balanced", "--bias-trend", "5e-9", "--bias-random-walk", "2e-8",
                        "--table-log-rate", "50", "--table-clock-offset", "0.05", "--table-clock-jitter", "0.001",
                        "--table-clock-step", "20", "0.02", "--table-clock-step", "60", "-0.03"],
                       check=True, timeout=600)
        with open(truth_path) as f:
            truth = yaml.safe_load(f)
        seqs, times, deviations, rates = [], [], [], []
        with rosbag.Bag(bag_path) as bag:
            for _, m, t in bag.read_messages(topics=["/turntable/state"]):
                true_time = t.to_sec() - 1.0  # written at its true time (the session starts at 1 s)
                clock = 0.05 + (0.02 if true_time >= 20.0 else 0.0) + (-0.03 if true_time >= 60.0 else 0.0)
                seqs.append(m.header.seq)
                times.append(true_time)
                deviations.append(m.header.stamp.to_sec() - t.to_sec() - clock)
                rates.append(m.rate)
        n = len(seqs)
        self.assertEqual(seqs, list(range(n)))
        self.assertTrue(all(abs(b - a - 0.02) < 1e-6 for a, b in zip(times, times[1:])), "one record per 20 ms")
        mean = sum(deviations) / n
        std = math.sqrt(sum((d - mean) ** 2 for d in deviations) / n)
        print("[ measured ] generator's table clock: %d records, jitter std %.4g s (asked 1e-3), mean %.3g s"
              % (n, std, mean))
        # Within 5 sigma of the estimates over n records (the stamps' rounding to 1 ns is negligible).
        self.assertAlmostEqual(mean, 0.0, delta=5 * 1e-3 / math.sqrt(n))
        self.assertAlmostEqual(std, 1e-3, delta=5 * 1e-3 / math.sqrt(2 * n))
        # Runs of the plateau rates: + then - (two plateaus and a reversal's time) then +.
        runs = []
        for t, r in zip(times, rates):
            sign = 1 if r == 0.4 else -1 if r == -0.4 else 0
            if sign and (not runs or runs[-1][0] != sign or t - runs[-1][2] > 0.03):
                runs.append([sign, t, t])
            elif sign:
                runs[-1][2] = t
        plateau = 3.0 + 2.0 * math.pi / (0.56 * 0.4)
        self.assertEqual([r[0] for r in runs], [1, -1, 1])
        self.assertAlmostEqual(runs[0][2] - runs[0][1], plateau, delta=0.03)
        self.assertAlmostEqual(runs[1][2] - runs[1][1], 2 * plateau + 1.6, delta=0.03)
        self.assertEqual(truth["plateau_order"], "balanced")
        drift = truth["bias_drift"]
        self.assertEqual((drift["rate"], drift["random_walk"]), (5e-9, 2e-8))
        (t0, d_start), (t_mid, _), (t_end, d_end) = drift["realised"]
        self.assertEqual((t0, d_start), (0.0, truth["drift"]["mean"]))
        self.assertAlmostEqual(t_end, truth["session_seconds"])
        # The walk's part of D0 at the end, 2e-8 sqrt(t_end) = 2.8e-7 rad/s (1 sigma): within 6 sigma.
        self.assertLess(abs(d_end - d_start - 5e-9 * t_end), 6 * 2e-8 * math.sqrt(t_end))
        self.assertEqual(truth["table_clock"], {"log_rate": 50.0, "offset": 0.05, "jitter": 0.001, "rate_error": 0.0,
                                                "steps": [[20.0, 0.02], [60.0, -0.03]]})


if __name__ == "__main__":
    rospy.init_node("independent_session_test")
    rostest.rosrun("hrg_gyro", "independent_session", IndependentSession)
