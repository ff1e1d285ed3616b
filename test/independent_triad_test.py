#!/usr/bin/env python3
"""Triad sessions from two makers read back the same way: test/independent_triad.py (numpy, written
without the package's simulator) and `hrg_bag simulate` on test/scenarios/triad_short.yaml. Each bag
must carry the triad's topics (/<axis>/channels at shared stamps, /turntable/state, /fixture/position)
with the right types, frames, counts and fixture log, and the injected triad must show in the wave
angles without a calibration: on every plateau pair each axis's theta moves by K0_i A_i . R^T times
the table's and the Earth's rotation (the up axis by its scale factor, the two others through their
misalignments, sign included), and at rest each axis drifts at K_i A_i . R^T omega_E + D_i (the
latitude, the azimuth and the position's orientation). The simulator's bag passing the same checks
from its scenario file as the generator's from its truth file says the two share every convention.
Both sessions are then calibrated by `hrg_bag calibrate --method triad`: the axis matrix must come out
within 5 urad and 3 reported sigmas of each maker's, each axis's K within 1 ppm of the generator's."""
import math
import os
import shutil
import subprocess
import sys
import unittest

import numpy as np
import rosbag
import rospy
import rostest
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import independent_triad as generator  # noqa: E402 (the generator's own frames: the test's reference)

AXES = generator.AXES
HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()


def harmonic(section):
    return generator.Harmonic(section["mean"], list(zip(section["orders"], section["cos"], section["sin"])))


def truth_from_generator(path):
    with open(path) as f:
        t = yaml.safe_load(f)
    return {
        "axes": t["axes"], "frame_id": t["frame_id"], "A": np.array(t["body_to_axis"]),
        "K": [harmonic(t["gyros"][a]["scale_factor"]) for a in t["axes"]],
        "D": [harmonic(t["gyros"][a]["drift"]) for a in t["axes"]],
        "latitude": t["latitude"], "azimuth": t["azimuth"],
        "positions": [{"name": p["name"], "R": np.array(p["body_to_table"])} for p in t["positions"]],
        "rate": t["rate"], "samples": int(round(t["session_seconds"] * t["output_hz"])) + 1,
        "records": int(round(t["session_seconds"] * t["log_hz"])) + 1,
    }


def truth_from_scenario(path):
    """What a triad scenario injects, read from its YAML by the test's own rules."""
    with open(path) as f:
        triad = yaml.safe_load(f)["triad"]
    axes = [a["name"] for a in triad["axes"]]
    body_to_axis = np.eye(3)
    for i, a in enumerate(triad["axes"]):
        body_to_axis[i, i] = 1.0 + a.get("scale", 0.0)
        body_to_axis[i, [j for j in range(3) if j != i]] = a["misalignment"]
    resonator = triad["axes"][0]["resonator"]
    hz = resonator["frequency"] / resonator["periods_per_output"]
    return {
        "axes": axes, "frame_id": triad["frame_id"], "A": body_to_axis,
        "K": [harmonic(a["resonator"]["scale_factor"]) for a in triad["axes"]],
        "D": [harmonic(a["resonator"]["drift"]) for a in triad["axes"]],
        "latitude": triad["turntable"]["latitude"], "azimuth": triad["turntable"]["azimuth"],
        "positions": [{"name": p["name"], "R": generator.up_rotation(p["up"])} for p in triad["positions"]],
        "rate": abs(triad["positions"][0]["profile"][1]["rates"][0]), "hz": hz,
    }


def read_session(path, truth):
    """Per sample: stamps and theta of each axis (decoded from the channels), the fixture's state, the
    table's angle and rate (interpolated from its records); and the raw messages for the checks."""
    with rosbag.Bag(path) as bag:
        info = bag.get_type_and_topic_info().topics
        channels = {a: [] for a in truth["axes"]}
        records, fixture = [], []
        topics = ["/%s/channels" % a for a in truth["axes"]] + ["/turntable/state", "/fixture/position"]
        for topic, m, _ in bag.read_messages(topics=topics):
            if topic == "/turntable/state":
                records.append(m)
            elif topic == "/fixture/position":
                fixture.append(m)
            else:
                channels[topic.split("/")[1]].append(m)
    s = {"info": info, "channels": channels, "records": records, "fixture": fixture}
    first = channels[truth["axes"][0]]
    s["t"] = np.array([m.header.stamp.to_sec() for m in first])
    s["theta"] = []
    for a in truth["axes"]:
        z = np.array([[m.c_in, m.c_quad, m.s_in, m.s_quad] for m in channels[a]])
        r = z[:, 0] ** 2 + z[:, 1] ** 2 - z[:, 2] ** 2 - z[:, 3] ** 2
        q = 2.0 * (z[:, 0] * z[:, 2] + z[:, 1] * z[:, 3])
        s["theta"].append(0.5 * np.unwrap(np.arctan2(q, r)))
    record_t = np.array([m.header.stamp.to_sec() for m in records])
    s["angle"] = np.interp(s["t"], record_t, [m.angle for m in records])
    s["rate"] = np.interp(s["t"], record_t, [m.rate for m in records])
    # The fixture's state at each sample: its messages come with the samples where it changes.
    fixture_t = np.array([m.header.stamp.to_sec() for m in fixture])
    k = np.searchsorted(fixture_t, s["t"], side="right") - 1
    s["position"] = np.array([fixture[j].index for j in k])
    s["locked"] = np.array([fixture[j].locked for j in k])
    return s


def runs(mask):
    """[start, end) index pairs of the runs of True."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(int), [0]))))
    return list(zip(edges[::2], edges[1::2]))


class IndependentTriad(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "independent_triad")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        package = rospy.get_param("~package_dir")
        gen_bag, gen_truth = os.path.join(cls.work, "generator.bag"), os.path.join(cls.work, "generator.truth.yaml")
        subprocess.run([sys.executable, os.path.join(HERE, "independent_triad.py"), "--out", gen_bag, "--truth",
                        gen_truth, "--encoder-noise", "2e-6", "--encoder-bits", "23"], check=True, timeout=900)
        scenario = os.path.join(package, "test", "scenarios", "triad_short.yaml")
        sim_bag = os.path.join(cls.work, "simulator.bag")
        p = subprocess.run([HRG_BAG, "simulate", "--scenario", scenario, "--out", sim_bag, "--no-truth"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=900)
        assert p.returncode == 0, p.stderr
        cls.generated_truth = truth_from_generator(gen_truth)
        cls.generated = read_session(gen_bag, cls.generated_truth)
        cls.simulated_truth = truth_from_scenario(scenario)
        cls.simulated = read_session(sim_bag, cls.simulated_truth)
        with open(gen_truth) as f:
            cls.truth_file = yaml.safe_load(f)

    def check_topics(self, s, truth, name):
        info, axes = s["info"], truth["axes"]
        for a in axes:
            self.assertEqual(info["/%s/channels" % a].msg_type, "hrg_gyro/ChannelAmplitudes")
        self.assertEqual(info["/turntable/state"].msg_type, "hrg_gyro/TurntableState")
        self.assertEqual(info["/fixture/position"].msg_type, "hrg_gyro/FixturePosition")
        # The three axes at the same stamps, none lost, each in its own frame.
        n = len(s["t"])
        for a in axes:
            msgs = s["channels"][a]
            self.assertEqual(len(msgs), n, a)
            self.assertEqual([m.header.seq for m in msgs], list(range(n)), a)
            self.assertEqual(set(m.header.frame_id for m in msgs), {a})
            np.testing.assert_array_equal([m.header.stamp.to_sec() for m in msgs], s["t"], a)
        if "samples" in truth:
            self.assertEqual(n, truth["samples"])
        else:  # the simulator: one sample per output period of the session
            self.assertAlmostEqual(n / truth["hz"], s["t"][-1] - s["t"][0] + 1.0 / truth["hz"], delta=1e-6)
        records = s["records"]
        self.assertEqual([m.header.seq for m in records], list(range(len(records))))
        self.assertEqual(len(records), truth.get("records", n))
        self.assertEqual(set(m.header.frame_id for m in s["fixture"]), {truth["frame_id"]})
        # The fixture's log: every position in order, named, with its nominal orientation; unlocked
        # exactly once before each position but the first; a message at least every second.
        fixture = s["fixture"]
        self.assertEqual(sorted(set(m.index for m in fixture)), list(range(len(truth["positions"]))))
        self.assertTrue(all(b.index >= a.index for a, b in zip(fixture, fixture[1:])))
        for m in fixture:
            p = truth["positions"][m.index]
            self.assertEqual(m.name, p["name"])
            q = generator.quaternion(p["R"])
            got = np.array([m.body_to_table.w, m.body_to_table.x, m.body_to_table.y, m.body_to_table.z])
            self.assertLess(min(np.abs(got - q).max(), np.abs(got + q).max()), 1e-9, (name, m.index))
        lock_changes = sum(a.locked != b.locked for a, b in zip(fixture, fixture[1:]))
        self.assertEqual(lock_changes, 2 * (len(truth["positions"]) - 1))
        self.assertFalse(any(not m.locked for m in fixture if m.index == 0))
        gaps = np.diff([m.header.stamp.to_sec() for m in fixture])
        self.assertLessEqual(gaps.max(), 1.0 + 1e-6)
        print("[ measured ] %s: %d samples per axis, %d table records, %d fixture messages" %
              (name, n, len(records), len(fixture)))

    def check_injected(self, s, truth, name):
        a_matrix, positions = truth["A"], truth["positions"]
        lat, az = truth["latitude"], truth["azimuth"]
        earth0 = generator.EARTH_RATE * np.array([math.cos(lat) * math.cos(az), math.cos(lat) * math.sin(az),
                                                  math.sin(lat)])
        t, angle = s["t"], s["angle"]
        hz = 1.0 / np.median(np.diff(t))
        window = int(round(hz))  # 1 s averages at the ends of each plateau
        worst_up, worst_cross, worst_rest = 0.0, 0.0, 0.0
        for k, p in enumerate(positions):
            r = p["R"]
            here = (s["position"] == k) & s["locked"]
            # The plateau pair: theta's moves on +rate minus those on -rate, against the exact motion.
            moved = {}
            for sign in (1.0, -1.0):
                start, end = max(runs(here & (np.abs(s["rate"] - sign * truth["rate"]) < 1e-12)),
                                 key=lambda e: e[1] - e[0])
                a_, b_ = start + window, end - window  # past the settling, before the ramp
                self.assertGreater(b_ - a_, 10 * window, (name, k, sign))
                tt, phi = t[a_:b_], angle[a_:b_]
                # The table frame's inertial rotation integrated over the window (centre to centre of
                # the averages): phidot e_z + Rz(phi)^T omega_E0.
                c, sn = np.cos(phi), np.sin(phi)
                platter = np.stack([c * earth0[0] + sn * earth0[1], -sn * earth0[0] + c * earth0[1],
                                    np.full_like(phi, earth0[2])], axis=1)
                inner = slice(window // 2, len(tt) - window // 2)
                rotation = np.trapz(platter[inner], tt[inner], axis=0)
                rotation[2] += phi[inner][-1] - phi[inner][0]
                moved[sign] = (rotation, [th[a_ + window // 2:b_ - window // 2] for th in s["theta"]], (a_, b_))
            for i in range(3):
                measured = []
                for sign in (1.0, -1.0):
                    a_, b_ = moved[sign][2]
                    th = s["theta"][i]
                    measured.append(np.mean(th[b_ - window:b_]) - np.mean(th[a_:a_ + window]))
                difference = measured[0] - measured[1]
                expected = truth["K"][i].mean * a_matrix[i] @ r.T @ (moved[1.0][0] - moved[-1.0][0])
                up = abs((r.T @ [0.0, 0.0, 1.0])[i]) > 0.5
                if up:
                    # The up axis: its mean scale factor over the sweep (harmonics below 5e-4 of K0).
                    worst_up = max(worst_up, abs(difference / expected - 1.0))
                    self.assertLess(abs(difference / expected - 1.0), 1e-3, (name, p["name"], i))
                else:
                    # A cross axis: its misalignment towards the up axis, 50 to 210 urad (sign included).
                    worst_cross = max(worst_cross, abs(difference - expected) / abs(expected))
                    self.assertLess(abs(difference - expected), 0.01 * abs(expected) + 1e-6,
                                    (name, p["name"], i, difference, expected))
            # At rest: K_i A_i . R^T Rz(phi)^T omega_E0 + D_i at the measured theta.
            start, end = max(runs(here & (s["rate"] == 0.0)), key=lambda e: e[1] - e[0])
            a_, b_ = start + 2 * window, end - 2 * window
            self.assertGreater(b_ - a_, 10 * window, (name, k))
            phi = np.mean(angle[a_:b_])
            earth = r.T @ np.array([math.cos(phi) * earth0[0] + math.sin(phi) * earth0[1],
                                    -math.sin(phi) * earth0[0] + math.cos(phi) * earth0[1], earth0[2]])
            for i in range(3):
                th = s["theta"][i][a_:b_]
                slope = np.polyfit(t[a_:b_] - t[a_], th, 1)[0]
                mid = float(np.mean(th))
                expected = truth["K"][i](mid) * a_matrix[i] @ earth + truth["D"][i](mid)
                worst_rest = max(worst_rest, abs(slope - expected))
                self.assertLess(abs(slope - expected), 2e-7 + 0.01 * abs(expected),
                                (name, p["name"], i, slope, expected))
        print("[ measured ] %s: up axes' scale within %.1e of K0, cross axes within %.1f %% of K0 A_ij, "
              "rest rates within %.1e rad/s" % (name, worst_up, 100 * worst_cross, worst_rest))

    def test_generator_writes_the_triad_topics(self):
        self.check_topics(self.generated, self.generated_truth, "generator")

    def test_generator_session_carries_the_injected_triad(self):
        self.check_injected(self.generated, self.generated_truth, "generator")

    def test_simulator_writes_the_same_topics(self):
        self.check_topics(self.simulated, self.simulated_truth, "simulator")

    def test_simulator_session_carries_its_scenario_triad(self):
        self.check_injected(self.simulated, self.simulated_truth, "simulator")

    def test_generator_truth_file_is_consistent(self):
        t = self.truth_file
        a, m = np.array(t["body_to_axis"]), np.array(t["axis_to_body"])
        np.testing.assert_allclose(a @ m, np.eye(3), atol=1e-15)
        self.assertEqual(t["misalignment"]["x"], [a[0, 1], a[0, 2]])
        self.assertEqual(t["misalignment"]["z"], [a[2, 0], a[2, 1]])
        self.assertEqual([p["up"] for p in t["positions"]], ["+z", "-z", "+x", "-x", "+y", "-y"])
        for p in t["positions"]:
            r = np.array(p["body_to_table"])
            np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-15)
            self.assertAlmostEqual(np.linalg.det(r), 1.0, places=15)
            axis = "xyz".index(p["up"][1])
            np.testing.assert_array_equal(r.T @ [0.0, 0.0, 1.0], (1.0 if p["up"][0] == "+" else -1.0) * np.eye(3)[axis])
            self.assertEqual(len(p["plateaus"]), 2)
        self.assertAlmostEqual(np.linalg.norm(t["earth_rate_table_zero"]), generator.EARTH_RATE, delta=1e-18)

    def calibrate(self, bag, name):
        """hrg_bag calibrate --method triad on a session, each axis's prior the shipped uncalibrated file."""
        out = os.path.join(self.work, name)
        os.makedirs(out, exist_ok=True)
        package = rospy.get_param("~package_dir")
        args = [HRG_BAG, "calibrate", bag, "--config", os.path.join(package, "test", "scenarios",
                                                                     "triad_short_calibration.yaml"),
                "--out", os.path.join(out, "triad.yaml"), "--report", os.path.join(out, "report.yaml")]
        for a in AXES:
            prior = os.path.join(out, "prior_%s.yaml" % a)
            shutil.copyfile(os.path.join(package, "config", "params_uncalibrated.yaml"), prior)
            args += ["--axis-params", "%s=%s" % (a, prior)]
        p = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        with open(os.path.join(out, "report.yaml")) as f:
            report = yaml.safe_load(f)
        with open(os.path.join(out, "triad.yaml")) as f:
            written = yaml.safe_load(f)
        return report, written, out

    def check_matrix(self, report, written, truth, name):
        """The axes' directions within 5 urad and 3 reported sigmas of the injected ones, M = A^-1 written."""
        self.assertTrue(report["accepted"], report["reason"])
        a_est, a_std = np.array(report["body_to_axis"]), np.array(report["body_to_axis_std"])
        off = ~np.eye(3, dtype=bool)
        error = (a_est - truth["A"])[off]
        print("[ measured ] %s: triad calibration, misalignment errors %s urad, sigmas %s urad" %
              (name, np.array2string(1e6 * error, precision=3), np.array2string(1e6 * a_std[off], precision=3)))
        self.assertLessEqual(np.abs(error).max(), 5e-6)
        self.assertTrue(np.all(np.abs(error) <= 3.0 * a_std[off]), (error, a_std[off]))
        np.testing.assert_allclose(np.array(written["axis_to_body"]) @ truth["A"], np.eye(3), atol=5e-6)
        # No body bias was injected: what the rests leave is within its sigmas.
        bias, bias_std = np.array(report["bias"]), np.array(report["bias_std"])
        self.assertTrue(np.all(np.abs(bias) <= 3.0 * bias_std), (bias, bias_std))

    def test_calibration_of_the_generator_session_finds_its_triad(self):
        report, written, out = self.calibrate(os.path.join(self.work, "generator.bag"), "generator_calibration")
        self.check_matrix(report, written, self.generated_truth, "generator")
        # Each axis's K(theta) against the generator's (ideal pickoffs: the intrinsic model is what the
        # processor sees), over the half turn of theta.
        theta = np.linspace(0.0, math.pi, 721)
        for i, a in enumerate(AXES):
            fit = report["axis_reports"][a]["scale_factor"][0]
            estimated = harmonic(fit)
            truth = self.generated_truth["K"][i]
            peak = max(abs(estimated(t) - truth(t)) for t in theta) / abs(truth.mean)
            print("[ measured ] generator: axis %s peak K error %.3f ppm" % (a, 1e6 * peak))
            self.assertLess(peak, 1e-6, a)
            with open(os.path.join(out, "%s.yaml" % a)) as f:
                self.assertEqual(yaml.safe_load(f)["calibration"]["method"], "triad")

    def test_calibration_of_the_simulator_session_finds_its_triad(self):
        report, written, _ = self.calibrate(os.path.join(self.work, "simulator.bag"), "simulator_calibration")
        self.check_matrix(report, written, self.simulated_truth, "simulator")


if __name__ == "__main__":
    rospy.init_node("independent_triad_test")
    rostest.rosrun("hrg_gyro", "independent_triad", IndependentTriad)
