#!/usr/bin/env python3
"""hrg_bag align, as a test engineer runs it on a recorded session: `hrg_bag simulate` of
test/scenarios/north_align.yaml (a triad at rest on an indexer at latitude 0.9 rad, the platter's x axis
at azimuth 2.0 rad = 114.59 deg true at table angle 0; 65 s there, a half turn, 65 s at pi), its axes'
channels through the processors and the triad's combiner (--triad, --axis-params with the gyros' exact
model). The static mode on the first 60 s and the indexed mode on both positions find the heading
within 3 reported sigmas of the truth; the result file reads back; the window's first 15, 30, 60 s give
sigmas that fall with the window; a moving table and a latitude beyond max_latitude are refused (exit 1)
naming their gate; bad settings and options exit 2 naming the key or option. The sweep of config/scenarios/north_sweep.yaml (its pickoffs' defects left
out; each axis's channels and precession state) finds the heading within 2 reported sigmas. Needs no master; run as a rostest for the
package environment."""
import math
import os
import random
import shutil
import subprocess
import unittest

import numpy
import rosbag
import rospy
import rostest
import yaml
from sensor_msgs.msg import Imu

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
AZIMUTH = 2.0  # rad, test/scenarios/north_align.yaml: the platter's x axis at table angle 0, from North to East

STATIC = """# The static triad levelled by a declared (exact) level, the first 60 s of the session.
mode: static                 # the triad at rest
latitude: 0.9                # rad, the scenario's
duration: 60.0               # s
noise:
  residual_bias: 1.0e-8      # rad/s, what a table calibration leaves (here the model is exact)
  angle_random_walk: 0.0     # rad/sqrt(s): the simulated gyros' angle noise is white only
  rate_random_walk: 0.0      # rad/s/sqrt(s): their bias does not wander
  residual_drift_harmonics: 0.0  # rad/s: the scenario's D is exact in the processors' files
level:
  source: declared           # no accelerometer in the session
  roll: 0.0                  # rad: the body on the platter, level
  pitch: 0.0                 # rad
  roll_sigma: 0.0            # rad: exactly level (the scenario's)
  pitch_sigma: 0.0           # rad
  accelerometer_bias_sigma: 0.0      # m/s^2: the one added below has white noise only
  accelerometer_mounting_sigma: 0.0  # rad: and sits on the body's axes
"""

INDEXED = """# The triad on the indexer, two positions 180 deg apart (the whole session).
mode: indexed                # the gyros' own bias cancels
latitude: 0.9                # rad
duration: 137.0              # s: both rests and the half turn between
noise:
  residual_bias: 1.0e-8      # rad/s (cancelled by the indexing)
  angle_random_walk: 0.0     # rad/sqrt(s): the simulated gyros' angle noise is white only
  rate_random_walk: 0.0      # rad/s/sqrt(s)
  residual_drift_harmonics: 0.0  # rad/s
level:
  source: declared           # the indexer's zero frame is level
  roll_sigma: 0.0            # rad: exactly (the scenario's)
  pitch_sigma: 0.0           # rad
indexer:
  settle: 1.0                # s after the half turn before samples count
"""

SWEEP = """# The sweep of config/scenarios/north_sweep.yaml, levelled by its accelerometer.
mode: sweep                  # each axis's wave turned through whole turns both ways
latitude: 0.9                # rad, the scenario's
duration: 270.0              # s: the field calibration's plan
noise:
  residual_drift_harmonics: 1.0e-8  # rad/s: the scenario's order-2 residual of D over |K0|, rms
  residual_bias: 0.0         # rad/s: the scenario has none
  angle_random_walk: 0.0     # rad/sqrt(s): the simulated gyros' angle noise is white only
  rate_random_walk: 0.0      # rad/s/sqrt(s)
level:
  source: accelerometer      # accel/data_raw
  accelerometer_to_body: {roll: 0.0, pitch: 0.0, yaw: 1.5707963267948966}  # rad: the scenario's mounting
  accelerometer_bias_sigma: 5.0e-4  # m/s^2: the scenario's bias is within it per axis
  accelerometer_mounting_sigma: 0.0 # rad: the scenario's mounting, exactly
"""

SWEEP_AXIS = """# A gyro of config/scenarios/north_sweep.yaml: its K0; D = 0 (the scenario's D is the residual).
schema_version: 1
scale_factor: {orders: [], mean: %r, cos: [], sin: []}
drift: {orders: [], mean: 0.0, cos: [], sin: []}
correction_matrix: {p: [0.0, 0.0, 0.0, 0.0]}
earth_rate: {enabled: false, latitude: 0.9}
calibration: {method: manual, time: "", source: "%s", notes: "K0 of the simulated gyro"}
"""

SWEEP_TRIAD = """# The triad of config/scenarios/north_sweep.yaml as a perfect calibration finds it: M = A^-1.
frame_id: imu_link
axes: [x, y, z]
axis_to_body:
  %s
bias: [0.0, 0.0, 0.0]
calibration: {method: manual, time: "", source: "", notes: "M = A^-1 of the scenario"}
"""


def run(*args, timeout=600):
    p = subprocess.run([HRG_BAG] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def heading_error_deg(heading, truth_deg):
    return (heading - truth_deg + 180.0) % 360.0 - 180.0


class HrgBagAlign(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "hrg_bag_align")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.pkg = rospy.get_param("~package_dir")
        cls.bag = cls.path("north_align.bag")
        code, _, err = run("simulate", "--scenario", os.path.join(cls.pkg, "test/scenarios/north_align.yaml"),
                           "--out", cls.bag, "--no-truth")
        assert code == 0, err
        axis = os.path.join(cls.pkg, "test/scenarios/north_align_axis.yaml")
        cls.chain = ["--triad", os.path.join(cls.pkg, "config/triad.yaml")]
        for name in "xyz":
            cls.chain += ["--axis-params", "%s=%s" % (name, axis)]
        cls.settings = {}
        for name, text in (("static", STATIC), ("indexed", INDEXED)):
            cls.settings[name] = cls.path(name + ".yaml")
            with open(cls.settings[name], "w") as f:
                f.write(text)

    @classmethod
    def path(cls, name):
        return os.path.join(cls.work, name)

    def align(self, settings, *extra):
        return run("align", self.bag, "--settings", settings, *(self.chain + list(extra)))

    def read(self, path):
        with open(path) as f:
            return yaml.safe_load(f)

    def check_heading(self, result, what):
        truth = math.degrees(AZIMUTH)
        error = heading_error_deg(result["heading_deg"], truth)
        sigma = result["heading_sigma_deg"]
        print("[ measured ] %s: heading %.5f deg +- %.5f deg (truth %.5f deg): error %.4f mrad, sigma %.4f mrad, "
              "%.2f sigma" % (what, result["heading_deg"], sigma, truth, 1e3 * math.radians(error),
                              1e3 * math.radians(sigma), abs(error) / sigma))
        self.assertLess(abs(error), 3.0 * sigma, what)

    def test_the_static_triad_finds_the_heading_and_its_sigma_falls_with_the_window(self):
        out = self.path("static.result.yaml")
        code, stdout, err = self.align(self.settings["static"], "--output", out, "--windows", "15,30,60")
        self.assertEqual(code, 0, stdout + err)
        self.assertRegex(stdout, r"true heading [0-9.]+ deg \+- [0-9.]+ deg \(1 sigma\)")
        r = self.read(out)
        self.assertTrue(r["accepted"])
        self.assertEqual(r["mode"], "static")
        self.assertEqual(r["frame"], "body")
        self.assertAlmostEqual(r["window"]["seconds"], 60.0, delta=0.01)
        self.check_heading(r, "static, 60 s")
        self.assertEqual(r["input"]["bag"], self.bag)
        windows = r["windows"]
        self.assertEqual([w["window_s"] for w in windows], [15.0, 30.0, 60.0])
        self.assertTrue(all(w["accepted"] for w in windows), windows)
        sigmas = [w["heading_sigma_deg"] for w in windows]
        noise = [w["noise_rad"] for w in windows]
        print("[ measured ] static, first 15, 30, 60 s: sigma %s deg, noise %s mrad" %
              (", ".join("%.5f" % s for s in sigmas), ", ".join("%.4f" % (1e3 * n) for n in noise)))
        self.assertTrue(sigmas[0] > sigmas[1] > sigmas[2], sigmas)
        self.assertTrue(noise[0] > noise[1] > noise[2], noise)
        # The whole window solved again (the result file carries its heading to 12 digits, the windows to 17).
        self.assertAlmostEqual(windows[-1]["heading_deg"], r["heading_deg"], delta=1e-8)
        for w in windows:
            self.assertLess(abs(heading_error_deg(w["heading_deg"], math.degrees(AZIMUTH))),
                            3.0 * w["heading_sigma_deg"], w)

    def test_the_indexed_triad_finds_the_heading_of_the_indexers_zero(self):
        out = self.path("indexed.result.yaml")
        code, stdout, err = self.align(self.settings["indexed"], "--output", out)
        self.assertEqual(code, 0, stdout + err)
        r = self.read(out)
        self.assertTrue(r["accepted"], r["reason"])
        self.assertEqual((r["mode"], r["frame"]), ("indexed", "indexer"))
        self.check_heading(r, "indexed, two positions of about 64 s")
        angles = sorted(s["indexer_angle_rad"] for s in r["segments"])
        self.assertEqual(len(angles), 2, r["segments"])
        self.assertAlmostEqual(angles[0], 0.0, delta=1e-6)
        self.assertAlmostEqual(angles[1], math.pi, delta=1e-6)
        self.assertEqual(r["windows"], [])

    def test_the_triads_recorded_output_gives_the_same_heading_and_an_accelerometer_levels_it(self):
        # The triad's output as the live triad node records it (hrg_bag process --triad --out): the same
        # records, so the same heading, bit for bit in the result file, as from the channels.
        processed = self.path("processed.bag")
        code, _, err = run("process", self.bag, "--out", processed, *self.chain)
        self.assertEqual(code, 0, err)
        from_channels, from_output = self.path("channels.result.yaml"), self.path("output.result.yaml")
        self.assertEqual(self.align(self.settings["static"], "--output", from_channels)[0], 0)
        code, stdout, err = run("align", processed, "--settings", self.settings["static"], "--output", from_output)
        self.assertEqual(code, 0, stdout + err)
        a, b = self.read(from_channels), self.read(from_output)
        for key in ("heading_deg", "heading_sigma_deg", "orientation", "covariance_enu_rad2", "segments"):
            self.assertEqual(a[key], b[key], key)
        # An accelerometer on the mount, level (+g up, 1e-3 m/s^2 of white noise at 100 Hz), on
        # accel/data_raw beside the triad's output: level/source accelerometer takes it.
        levelled = self.path("levelled.bag")
        noise = random.Random(7)
        with rosbag.Bag(processed) as source, rosbag.Bag(levelled, "w") as out:
            start = None
            for topic, message, t in source.read_messages(topics=["/triad/output"]):
                out.write(topic, message, t)
                start = start or message.header.stamp
            stamp = start
            while stamp < t:
                imu = Imu()
                imu.header.stamp = stamp
                imu.header.frame_id = "imu_link"
                f = imu.linear_acceleration
                f.x, f.y, f.z = noise.gauss(0.0, 1e-3), noise.gauss(0.0, 1e-3), 9.80665 + noise.gauss(0.0, 1e-3)
                out.write("/accel/data_raw", imu, stamp)
                stamp += rospy.Duration(0.01)
        accelerometer = self.path("accelerometer.yaml")
        with open(accelerometer, "w") as f:
            f.write(STATIC.replace("  source: declared           # no accelerometer in the session",
                                   "  source: accelerometer      # accel/data_raw")
                    .replace("  roll: 0.0                  # rad: the body on the platter, level\n", "")
                    .replace("  pitch: 0.0                 # rad\n", ""))
        result = self.path("accelerometer.result.yaml")
        code, stdout, err = run("align", levelled, "--settings", accelerometer, "--output", result)
        self.assertEqual(code, 0, stdout + err)
        self.assertRegex(err, r" [1-9][0-9]{3} accelerometer records")
        r = self.read(result)
        self.assertAlmostEqual(r["accelerometer_gravity_m_s2"], 9.80665, delta=1e-3)
        self.assertLess(abs(r["attitude_rad"]["roll"]), 1e-5)
        self.check_heading(r, "static, 60 s, levelled by the accelerometer")
        # Asked for and absent: refused naming the topic it looked for.
        code, _, err = run("align", processed, "--settings", accelerometer)
        self.assertEqual(code, 2, err)
        self.assertIn("accel/data_raw", err)

    def test_one_gyro_on_the_indexer_finds_the_heading_from_four_positions(self):
        # The session's x gyro alone (horizontal, along the platter's x), its outputs as its processor
        # node publishes them (hrg_bag process --triad --out), on four positions 90 deg apart of 30 s.
        with open(os.path.join(self.pkg, "test/scenarios/north_align.yaml")) as f:
            text = f.read()
        step = "{type: steps, angle: 3.141592653589793, rate: 0.5, dwell: 65.0, count: 1, label: index}"
        self.assertIn(step, text)
        scenario, bag = self.path("four.yaml"), self.path("four.bag")
        with open(scenario, "w") as f:
            f.write(text.replace(step, step.replace("3.141592653589793", "1.5707963267948966")
                                 .replace("65.0", "30.0").replace("count: 1", "count: 3")))
        self.assertEqual(run("simulate", "--scenario", scenario, "--out", bag, "--no-truth")[0], 0)
        processed, gyro = self.path("four_processed.bag"), self.path("four_gyro.bag")
        code, _, err = run("process", bag, "--out", processed, *self.chain)
        self.assertEqual(code, 0, err)
        with rosbag.Bag(processed) as a, rosbag.Bag(bag) as b, rosbag.Bag(gyro, "w") as out:
            for topic, message, t in a.read_messages(topics=["/x/output"]):
                out.write(topic, message, t)
            for topic, message, t in b.read_messages(topics=["/turntable/state"]):
                out.write(topic, message, t)
        settings = self.path("single.yaml")
        with open(settings, "w") as f:
            f.write(INDEXED.replace("duration: 137.0              # s: both rests and the half turn between",
                                    "duration: 132.0              # s: four rests and three quarter turns")
                    + "single_gyro: true            # the x gyro alone\n")
        result = self.path("single.result.yaml")
        code, stdout, err = run("align", gyro, "--settings", settings, "--output", result)
        self.assertEqual(code, 0, stdout + err)
        self.assertIn("(one gyro)", stdout)
        r = self.read(result)
        self.assertEqual((r["mode"], r["single_gyro"], r["frame"], len(r["segments"])), ("indexed", True, "indexer", 4))
        self.check_heading(r, "one gyro, indexed, four positions of about 29 s")
        # Two of the gyro's outputs in the bag: the one to align names itself.
        code, _, err = run("align", processed, "--settings", settings)
        self.assertEqual(code, 2, err)
        self.assertIn("gyro-topic", err)

    def test_a_moving_base_is_tracked_offline_as_live(self):
        # config/scenarios/north_try.yaml (a standing vehicle whose engine runs; gyros the uncalibrated
        # chain measures), its first 120 s recorded with its accelerometer and truth: the tracking
        # estimator answers, within 3 sigmas of the truth's heading at the window's last sample.
        bag = self.path("north_try.bag")
        code, _, err = run("simulate", "--scenario", os.path.join(self.pkg, "config/scenarios/north_try.yaml"),
                           "--out", bag)
        self.assertEqual(code, 0, err)
        chain = ["--triad", os.path.join(self.pkg, "config/triad.yaml")]
        for name in "xyz":
            chain += ["--axis-params", "%s=%s" % (name, os.path.join(self.pkg, "config/params_uncalibrated.yaml"))]
        settings, out = self.path("moving.yaml"), self.path("moving.result.yaml")
        with open(settings, "w") as f:
            f.write(STATIC.replace("duration: 60.0               # s", "duration: 120.0              # s")
                    .replace("  source: declared           # no accelerometer in the session",
                             "  source: accelerometer      # accel/data_raw")
                    .replace("  accelerometer_bias_sigma: 0.0      # m/s^2: the one added below has white noise only",
                             "  accelerometer_bias_sigma: 5.0e-4   # m/s^2: the scenario's bias is within it"))
        code, stdout, err = run("align", bag, "--settings", settings, "--output", out, *chain)
        self.assertEqual(code, 0, stdout + err)
        r = self.read(out)
        self.assertEqual(r["estimator"], "tracking", r["estimator_reason"])
        last = r["window"]["last_sample_ns"]
        with rosbag.Bag(bag) as b:
            truth = [m.body_to_enu for _, m, _ in b.read_messages(topics=["/truth"]) if m.header.stamp.to_nsec() == last]
        self.assertEqual(len(truth), 1, "no truth at the last sample's stamp")
        q = truth[0]
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        error, sigma = heading_error_deg(r["heading_deg"], (90.0 - math.degrees(yaw)) % 360.0), r["heading_sigma_deg"]
        print("[ measured ] moving base offline, 120 s, tracking: error %+.4f mrad, sigma %.4f mrad (z %+.2f)" %
              (1e3 * math.radians(error), 1e3 * math.radians(sigma), error / sigma))
        self.assertLess(abs(error), 3.0 * sigma)
        self.assertTrue(all(c["passed"] for c in r["earth_checks"]), r["earth_checks"])

    def test_the_sweep_of_config_north_sweep_finds_the_heading_from_each_axis_and_its_precession(self):
        # config/scenarios/north_sweep.yaml: each axis's wave turned + - - + by its precession loop, its
        # /<axis>/precession/state recorded beside its channels. Its pickoffs without their defects here,
        # so that the processors' files (each axis's K0, D = 0: the scenario's D is the residual the sweep
        # averages out; the correction matrix none) are the gyros' exact model; the triad file M = A^-1.
        shipped = os.path.join(self.pkg, "config/scenarios/north_sweep.yaml")
        document = yaml.safe_load(open(shipped))
        for axis in document["triad"]["axes"]:
            axis["pickoff"] = {"noise": axis["pickoff"]["noise"]}
        scenario_path = self.path("north_sweep.yaml")
        with open(scenario_path, "w") as f:
            yaml.safe_dump(document, f)
        bag = self.path("north_sweep.bag")
        code, _, err = run("simulate", "--scenario", scenario_path, "--out", bag, "--no-truth")
        self.assertEqual(code, 0, err)
        with rosbag.Bag(bag) as b:
            topics = b.get_type_and_topic_info().topics
        for name in "xyz":
            state = topics["/%s/precession/state" % name]
            self.assertEqual(state.msg_type, "hrg_gyro/PrecessionState")
            self.assertEqual(state.message_count, topics["/%s/channels" % name].message_count)
        scenario = document["triad"]
        chain = ["--triad", self.path("north_sweep_triad.yaml")]
        a = numpy.identity(3)
        for i, axis in enumerate(scenario["axes"]):
            others = [j for j in range(3) if j != i]
            a[i, others[0]], a[i, others[1]] = axis["misalignment"]
            k0 = -2.0 * axis["dynamics"]["shell"]["bryan_factor"]
            params = self.path("north_sweep_%s.yaml" % axis["name"])
            with open(params, "w") as f:
                f.write(SWEEP_AXIS % (k0, scenario_path))
            chain += ["--axis-params", "%s=%s" % (axis["name"], params)]
        with open(chain[1], "w") as f:
            f.write(SWEEP_TRIAD % yaml.safe_dump(numpy.linalg.inv(a).tolist(), default_flow_style=None).strip()
                    .replace("\n", "\n  "))
        settings, out = self.path("sweep.yaml"), self.path("sweep.result.yaml")
        with open(settings, "w") as f:
            f.write(SWEEP)
        code, stdout, err = run("align", bag, "--settings", settings, "--output", out, *chain)
        self.assertEqual(code, 0, stdout + err)
        r = self.read(out)
        self.assertEqual(r["mode"], "sweep")
        truth = math.degrees(scenario["turntable"]["azimuth"] - scenario["positions"][0]["body_to_table"]["yaw"])
        error, sigma = heading_error_deg(r["heading_deg"], truth), r["heading_sigma_deg"]
        print("[ measured ] sweep, 270 s from the axes' channels: heading %.5f deg +- %.5f deg (truth %.5f deg): "
              "error %.4f mrad, sigma %.4f mrad" % (r["heading_deg"], sigma, truth, 1e3 * math.radians(error),
                                                    1e3 * math.radians(sigma)))
        self.assertLess(abs(error), 2.0 * sigma)
        # Without the triad's chain there are no axis outputs to sweep: refused naming the option.
        code, _, err = run("align", bag, "--settings", settings)
        self.assertEqual(code, 2, err)
        self.assertIn("--triad", err)

    def test_a_moving_table_and_a_latitude_beyond_the_limit_are_refused_naming_the_gate(self):
        out = self.path("moving.result.yaml")
        # The static mode over the half turn (65 s to 72 s): the motion gate, as the samples come.
        code, stdout, err = self.align(self.settings["static"], "--duration", "100", "--output", out)
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("alignment refused (motion)", stdout)
        r = self.read(out)
        self.assertEqual((r["accepted"], r["gate"]), (False, "motion"))
        far_north = self.path("far_north.yaml")
        with open(far_north, "w") as f:
            f.write(STATIC + "max_latitude: 0.5          # rad: below the site's 0.9\n")
        code, stdout, err = self.align(far_north)
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("alignment refused (latitude)", stdout)
        # The bag ends before the window is full: refused, saying how far it got.
        code, stdout, err = self.align(self.settings["indexed"], "--duration", "500")
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("the bag ended after", stdout)

    def test_bad_settings_and_options_are_refused_by_name(self):
        bad = self.path("bad.yaml")
        with open(bad, "w") as f:
            f.write(STATIC.replace("  roll: 0.0 ", "  rol: 0.0  "))
        # Settings that read an Allan file: --output onto that file is refused (it is an input), and
        # nothing is written over it.
        allan, allan_settings = self.path("allan.yaml"), self.path("with_allan.yaml")
        with open(allan, "w") as f:
            f.write("# hrg_bag allan readings\nsamples: 72000\ntau0: 0.005\nrecord_length: 360.0\n"
                    "angle_white_noise: {identified: true, value: 8.75e-6, tau_min: 0.005, tau_max: 1.0}\n"
                    "angle_random_walk: {identified: false, value: 0.0, tau_min: 0.0, tau_max: 0.0}\n"
                    "bias_instability: {identified: false, value: 0.0, tau_min: 0.0, tau_max: 0.0}\n"
                    "rate_random_walk: {identified: false, value: 0.0, tau_min: 0.0, tau_max: 0.0}\n")
        with open(allan_settings, "w") as f:
            f.write(STATIC.replace("noise:\n", "noise:\n  allan_file: allan.yaml\n"))
        # No noise model at all: refused naming the first term not given, nothing claimed.
        unmeasured = self.path("unmeasured.yaml")
        with open(unmeasured, "w") as f:
            f.write("mode: static\nlatitude: 0.9\nlevel: {source: declared, roll_sigma: 0.0, pitch_sigma: 0.0}\n")
        cases = [
            (["--settings", bad], "rol"),
            (["--settings", self.settings["static"], "--windows", "30,90"], "--windows"),
            (["--settings", self.settings["static"], "--windows", "30,15"], "--windows"),
            (["--settings", self.settings["static"], "--duration", "-1"], "--duration"),
            (["--settings", self.settings["static"], "--output", self.bag], "refused"),
            (["--settings", allan_settings, "--output", allan], "refused"),
            (["--settings", unmeasured], "noise.angle_random_walk"),
            (["--settings", self.settings["static"], "--triad-topic", "/triad/output"], "triad-topic"),
        ]
        for extra, fragment in cases:
            args = ["align", self.bag] + extra
            if "--triad-topic" not in extra:
                args += self.chain
            code, stdout, err = run(*args)
            self.assertEqual(code, 2, (args, stdout, err))
            self.assertIn(fragment, err, args)
        self.assertTrue(os.path.getsize(self.bag) > 0)
        with open(allan) as f:
            self.assertIn("8.75e-6", f.read())


if __name__ == "__main__":
    rospy.init_node("hrg_bag_align_test")
    rostest.rosrun("hrg_gyro", "hrg_bag_align", HrgBagAlign)
