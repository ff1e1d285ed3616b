#!/usr/bin/env python3
"""North from an IMU's log with the package's commands alone (docs/north_from_your_imu_log.md):
hrg_bag import --imu, hrg_bag allan --imu-topic, hrg_bag align with config/gyrocompass_psins_lasergyro.yaml.

- The shipped excerpt of the PSINS toolbox's ring-laser-gyro log (test/data, 600 to 900 s of a vehicle
  standing with its disturbances): the window accepted by the tracking estimator, its heading that of
  the whole log's same samples (90.5823 deg) and the header's 90.6 deg within its sigma; the three
  checks against the Earth passed; allan prints each axis and the bound on N; --scan over the
  excerpt's two 140 s windows agrees within its sigma.
- Logs of the same format written by test/psins_log_generator.py (numpy, none of the package's code: a
  still body at a known heading, roll and pitch, 0.1 arcsec and 125 ug*s counts, a gyro bias and angle
  random walk): for three seeds and both estimators, each accepted heading within 3 sigma of the truth
  with the generator's noise given (the still-base fit answers every time; the tracking estimator may
  refuse, naming why)."""
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
EPOCH = "1395394311"  # s: the log's date, 2014-03-21
WHOLE_LOG_WINDOW = 90.5823  # deg: hrg_bag align --start 600 --duration 290 on the whole log (the same samples)


def run(*args):
    p = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                       timeout=300)
    return p.returncode, p.stdout, p.stderr


def wrap(d):
    return (d + 180.0) % 360.0 - 180.0


class NorthFromImuLog(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "north_from_imu_log")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.pkg = rospy.get_param("~package_dir")
        cls.settings = os.path.join(cls.pkg, "config", "gyrocompass_psins_lasergyro.yaml")

    def path(self, name):
        return os.path.join(self.work, name)

    def imported(self, log, name):
        bag = self.path(name + ".bag")
        code, out, err = run(HRG_BAG, "import", "--imu", log, "--format", "psins", "--epoch", EPOCH, "--out", bag,
                             "--quiet")
        self.assertEqual(code, 0, out + err)
        return bag

    def test_the_real_logs_excerpt_gives_the_whole_logs_heading(self):
        bag = self.imported(os.path.join(self.pkg, "test", "data", "psins_lasergyro_excerpt.imu"), "excerpt")
        code, out, err = run(HRG_BAG, "allan", bag, "--imu-topic", "/imu/data_raw", "--yaml", self.path("allan.yaml"))
        self.assertEqual(code, 0, err)
        self.assertEqual(out.count("N at most"), 3, out)
        readings = yaml.safe_load(open(self.path("allan.yaml")))
        self.assertEqual(sorted(readings["axes"]), ["x", "y", "z"])
        self.assertAlmostEqual(readings["tau0"], 0.01, delta=1e-9)

        result = self.path("excerpt.alignment.yaml")
        # 30 000 rows hold 299.99 s of intervals (the first row starts the stream): 290 s windows.
        code, out, err = run(HRG_BAG, "align", bag, "--settings", self.settings, "--duration", "290", "--output",
                             result)
        self.assertEqual(code, 0, out + err)
        r = yaml.safe_load(open(result))
        print("excerpt: heading %.4f +- %.4f deg (%s), the whole log's window %.4f, the header's 90.6; earth checks %s" %
              (r["heading_deg"], r["heading_sigma_deg"], r["estimator"], WHOLE_LOG_WINDOW,
               [(c["name"], round(c["measured"], 9), round(c["expected"], 9)) for c in r["earth_checks"]]))
        self.assertTrue(r["accepted"])
        self.assertEqual(r["estimator"], "tracking")
        self.assertAlmostEqual(r["heading_deg"], WHOLE_LOG_WINDOW, delta=1e-4)
        self.assertLess(abs(wrap(r["heading_deg"] - 90.6)), r["heading_sigma_deg"])
        self.assertTrue(all(c["passed"] for c in r["earth_checks"]))

        code, out, err = run(HRG_BAG, "align", bag, "--settings", self.settings, "--duration", "140", "--scan", "145",
                             "--output", self.path("scan.yaml"))
        self.assertEqual(code, 0, out + err)
        scan = yaml.safe_load(open(self.path("scan.yaml")))
        print("excerpt, 140 s windows: %s" % [(w["start_s"], round(w.get("heading_deg", float("nan")), 4))
                                               for w in scan["windows"]])
        self.assertEqual(len(scan["windows"]), 2)
        self.assertTrue(all(w["accepted"] for w in scan["windows"]))
        self.assertLess(scan["largest_consecutive_difference_deg"], scan["windows"][0]["heading_sigma_deg"])

    def test_generated_logs_of_the_same_format_against_their_truth(self):
        generator = os.path.join(self.pkg, "test", "psins_log_generator.py")
        worst, refusals = 0.0, 0
        for seed, heading in ((1, 90.6), (2, 212.3), (3, 333.9)):
            log, truth_file = self.path("gen%d.imu" % seed), self.path("gen%d.truth.yaml" % seed)
            code, out, err = run(sys.executable, generator, "--out", log, "--truth", truth_file, "--seconds", "300",
                                 "--heading", str(heading), "--seed", str(seed))
            self.assertEqual(code, 0, err)
            truth = yaml.safe_load(open(truth_file))
            bag = self.imported(log, "gen%d" % seed)
            for estimator in ("still_base", "tracking"):
                settings = self.path("gen%d.%s.settings.yaml" % (seed, estimator))
                with open(settings, "w") as f:
                    f.write("latitude: %.12f\nduration: 290.0\ngyro_input: imu\nestimator: %s\n" %
                            (truth["latitude"], estimator))
                    f.write("noise: {angle_white_noise: -1.0, angle_quantum: %.9e, angle_random_walk: %.6e,"
                            " rate_random_walk: 0.0, residual_bias: 4.0e-8, residual_drift_harmonics: 0.0}\n" %
                            (truth["angle_quantum"], truth["angle_random_walk"]))
                    f.write("level: {source: accelerometer, accelerometer_bias_sigma: 1.0e-3,"
                            " accelerometer_mounting_sigma: 0.0}\n")
                result = self.path("gen%d.%s.alignment.yaml" % (seed, estimator))
                code, out, err = run(HRG_BAG, "align", bag, "--settings", settings, "--output", result)
                r = yaml.safe_load(open(result))
                if estimator == "tracking" and code == 1:
                    # A north finder answers with an honest sigma or refuses naming why: a refusal counts as
                    # no answer, never as a wrong one. The still base must answer.
                    print("generated, seed %d, tracking: refused (%s): %s" % (seed, r["gate"], r["reason"]))
                    self.assertNotEqual(r["gate"], "")
                    refusals += 1
                    continue
                self.assertEqual(code, 0, out + err)
                z = wrap(r["heading_deg"] - truth["heading_deg"]) / r["heading_sigma_deg"]
                print("generated, seed %d, %s: heading %.4f +- %.4f deg against %.4f: z = %+.2f; roll %+.6f pitch "
                      "%+.6f (truth %+.6f %+.6f)" %
                      (seed, estimator, r["heading_deg"], r["heading_sigma_deg"], truth["heading_deg"], z,
                       r["attitude_rad"]["roll"], r["attitude_rad"]["pitch"], truth["roll"], truth["pitch"]))
                worst = max(worst, abs(z))
                self.assertLess(abs(z), 3.0)
                self.assertAlmostEqual(r["attitude_rad"]["roll"], truth["roll"], delta=3e-4)
                self.assertAlmostEqual(r["attitude_rad"]["pitch"], truth["pitch"], delta=3e-4)
        print("generated logs: worst |z| %.2f of what was accepted over 3 seeds and both estimators; the tracking "
              "refused %d of 3" % (worst, refusals))
        self.assertLessEqual(refusals, 2, "the tracking estimator answers on a still base at least once in three")


if __name__ == "__main__":
    rospy.init_node("north_from_imu_log_test", anonymous=True)
    rostest.rosrun("hrg_gyro", "north_from_imu_log", NorthFromImuLog)
