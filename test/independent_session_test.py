#!/usr/bin/env python3
"""Simulator-independent check of the calibration: sessions made by test/independent_session.py (its
own dynamics, channel model and table log, no truth topic) are calibrated by `hrg_bag calibrate` with
the nominal prior, and the fitted K is compared with the injected one: the peak over theta of
|K_fit - K_injected - (K0_fit - K0_injected)| and the K0 error, both <= 1 ppm of |K0|.

Cases: the shipped gyro's magnitudes with an encoder-logged angle, a slow drive (40 s ramps), a
strong nonlinearity (3 % cos 4theta, 0.3 % cos 8theta) and a real table log (strong nonlinearity,
0.2 % drive ripple, the rate logged as the differenced encoder angle)."""
import math
import os
import shutil
import subprocess
import sys
import unittest

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
        """Generates the session and calibrates it; returns (residual nonlinearity, K0 error), ppm of |K0|."""
        bag, truth = os.path.join(self.work, name + ".bag"), os.path.join(self.work, name + ".truth.yaml")
        out = os.path.join(self.work, name + ".yaml")
        subprocess.run([sys.executable, GENERATOR, "--out", bag, "--truth", truth] + list(generator_args),
                       check=True, timeout=600)
        p = subprocess.run([HRG_BAG, "calibrate", bag, "--method", "dual_rate", "--params", self.params,
                            "--out", out], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=600)
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


if __name__ == "__main__":
    rospy.init_node("independent_session_test")
    rostest.rosrun("hrg_gyro", "independent_session", IndependentSession)
