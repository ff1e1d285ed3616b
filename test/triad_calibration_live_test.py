#!/usr/bin/env python3
"""The triad calibration live against the same session offline (test/triad_calibration_live.test).

Offline first: `hrg_bag simulate` of the scenario with the launch's seed into a bag, then
`hrg_bag calibrate --method triad` on it from the same priors and settings (the shipped
test/scenarios/triad_short_calibration.yaml, which the launch loads into the calibrator too). Then the test subscribes
to /turntable/state, which lets driver_sim start (it waits for two turntable listeners): the same
samples (the simulator is deterministic: same scenario and seed, same channels bit for bit) go
through three live processors into the calibrator. Once the calibrator's diagnostic says every
record of the bag's streams has arrived, ~finish; the result must be accepted, written (the three
axis files then the triad file), each processor reloaded (its ModelInfo says triad), the files must
hold what ~result says and the replaced ones their .bak, and M, the bias and each axis's K must be
the offline ones (tolerances below, with why). Two stray fixture records, published by the test once
the session runs (the last position stamped 1000 s ahead and 100 s back, as a bench's clock glitch or
a buffered message makes them), are dropped and counted: the run never restarts and the result is
the offline one all the same."""
import copy
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospy
import rostest
from std_srvs.srv import Trigger

from hrg_gyro.msg import FixturePosition, ModelInfo, TriadCalibrationResult, TurntableState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
AXES = ("x", "y", "z")
STREAMS = ("axis x", "axis y", "axis z", "turntable", "fixture")


def run(*args):
    p = subprocess.run([HRG_BAG] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def matrix(rows):
    return [float(v) for row in rows for v in row]


class TriadCalibrationLive(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="hrg_triad_live.")
        self.files = rospy.get_param("~files")
        self.priors = rospy.get_param("~priors")
        # The calibrator's counters of records received go on while it works through its queues.
        self.diagnostic = util.Diagnostic("triad calibration", ["%s received" % k for k in STREAMS])

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    @property
    def status(self):
        return self.diagnostic.values

    def offline(self):
        """The reference: the bag of the same scenario and seed, calibrated by hrg_bag."""
        bag = os.path.join(self.tmp, "session.bag")
        code, _, err = run("simulate", "--scenario", rospy.get_param("~scenario"), "--seed",
                           str(rospy.get_param("~seed")), "--out", bag)
        self.assertEqual(code, 0, err)
        settings = rospy.get_param("~settings")  # the calibrator's too (the launch loads it)
        args = ["calibrate", "--method", "triad", bag, "--triad", os.path.join(self.priors, "triad.yaml"),
                "--config", settings, "--out", os.path.join(self.tmp, "triad.yaml"),
                "--report", os.path.join(self.tmp, "report.yaml"), "--axis-params"]
        args += ["%s=%s" % (a, os.path.join(self.priors, "params_uncalibrated.yaml")) for a in AXES]
        args += ["--axis-out"] + ["%s=%s" % (a, os.path.join(self.tmp, a + ".yaml")) for a in AXES]
        code, out, err = run(*args)
        self.assertEqual(code, 0, out + err)
        with rosbag.Bag(bag) as b:
            topics = b.get_type_and_topic_info().topics
            counts = {"axis %s" % a: topics["/%s/channels" % a].message_count for a in AXES}
            counts["turntable"] = topics["/turntable/state"].message_count
            counts["fixture"] = topics["/fixture/position"].message_count
        return counts, util.load_yaml(os.path.join(self.tmp, "report.yaml"))

    def test_live_triad_calibration_matches_offline(self):
        counts, reference = self.offline()
        self.assertTrue(reference["accepted"], reference["reason"])
        results = util.Latest("/calibrator/result", TriadCalibrationResult)
        models = {a: util.Latest("/%s/processor/model" % a, ModelInfo) for a in AXES}

        # Let the driver start, and see every record arrive.
        gate = rospy.Subscriber("/turntable/state", TurntableState, lambda m: None, queue_size=1)
        util.wait_for(lambda: self.status.get("run") == "running" and
                      self.status.get("turntable received", "0") != "0", "the session to start")
        gate.unregister()

        # Two stray fixture records: the position in force, stamped 1000 s ahead and 100 s back.
        fixture = util.Latest("/fixture/position", FixturePosition)
        stray = rospy.Publisher("/fixture/position", FixturePosition, queue_size=2)
        util.wait_for(lambda: fixture.msg is not None and rospy.get_rostime().to_sec() > 120.0, "a fixture record past 120 s of the session")
        util.wait_for(lambda: stray.get_num_connections() >= 2, "the calibrator's subscription to the strays")
        for offset in (1000.0, -100.0):
            m = copy.deepcopy(fixture.msg)
            m.header.stamp = rospy.Time.from_sec(m.header.stamp.to_sec() + offset)
            stray.publish(m)
            rospy.sleep(rospy.Duration(0.5))
        counts["fixture"] += 2

        def arrived():
            return all(self.status.get(k + " received") == str(n) for k, n in counts.items())
        # However long the session takes in wall time: fails only when it stops moving.
        util.wait_for(arrived, lambda: "every record at the calibrator: %r (diagnostic: %r)" % (counts, self.status))
        late = {}
        for key in STREAMS:
            for drop in ("dropped (zero stamp)", "dropped (out of order)", "dropped (stamp jump)"):
                expected = "2" if (key, drop) == ("fixture", "dropped (stamp jump)") else "0"
                self.assertEqual(self.status.get("%s %s" % (key, drop)), expected, key + " " + drop)
            late[key] = self.status.get(key + " fed late (behind later stamps)")
        self.assertEqual(self.status.get("restarts (time went backwards)"), "0")
        print("records fed late (a stream lagged beyond ~stream_hold): %r" % late)

        finish = rospy.ServiceProxy("/calibrator/finish", Trigger)
        answer = finish()
        self.assertTrue(answer.success, answer.message)
        util.wait_for(lambda: results.msg is not None, "~result")
        r = results.msg
        self.assertTrue(r.accepted, r.reason)
        self.assertTrue(r.written, r.reason)
        self.assertEqual(r.reason, "")
        expected = [os.path.join(self.files, a + ".yaml") for a in AXES] + [os.path.join(self.files, "triad.yaml")]
        self.assertEqual(list(r.files_written), expected)
        self.assertEqual(list(r.reloaded), ["/%s/processor/reload" % a for a in AXES])
        self.assertEqual(list(r.reload_failed), [])
        self.assertEqual(r.positions_fitted, 6)
        self.assertTrue(r.bias_estimated)
        self.assertEqual(list(r.axis_accepted), [True, True, True])
        for a in AXES:
            util.wait_for(lambda: models[a].msg and models[a].msg.calibration_method == "triad",
                          "processor %s to run its new file" % a)

        # The files hold what ~result says; each replaced one is kept as .bak (the priors).
        triad = util.load_yaml(os.path.join(self.files, "triad.yaml"))
        self.assertEqual(triad["calibration"]["method"], "triad")
        self.assertEqual(triad["calibration"]["source"], "live")
        self.assertEqual(triad["axes"], list(AXES))
        self.assertEqual(matrix(triad["axis_to_body"]), list(r.axis_to_body))
        self.assertEqual([float(v) for v in triad["bias"]], list(r.bias))
        with open(os.path.join(self.files, "triad.yaml.bak")) as f, \
                open(os.path.join(self.priors, "triad.yaml")) as g:
            self.assertEqual(f.read(), g.read())
        live_axes = {}
        for a in AXES:
            live_axes[a] = util.load_yaml(os.path.join(self.files, a + ".yaml"))
            self.assertEqual(live_axes[a]["calibration"]["method"], "triad")
            self.assertTrue(os.path.exists(os.path.join(self.files, a + ".yaml.bak")))
        report = util.load_yaml(r.report_file)
        self.assertTrue(report["accepted"])

        # Live against offline. The bag and the live topics carry the same samples (deterministic
        # simulator, counts checked above), the processors are the same code on the same settings,
        # and the calibrator feeds the core in stamp order as hrg_bag reads the bag: the results
        # agree to far below their own standard errors. What may differ: which of the records of one
        # stamp comes first (hrg_bag: the bag's order; live: fixture, table, axes), and where the
        # fixture state changes at a stamp that also carries samples; both fall in rests or moves, which
        # no estimate uses. Tolerance: 1 % of the smallest standard error of M (about 3e-9 here).
        m_live, m_offline = list(r.axis_to_body), matrix(reference["axis_to_body"])
        sigma = min(matrix(reference["axis_to_body_std"]))
        worst = max(abs(p - q) for p, q in zip(m_live, m_offline))
        print("live vs offline: largest |M_live - M_offline| %.3g (smallest sigma of M %.3g)" % (worst, sigma))
        self.assertLessEqual(worst, 0.01 * sigma)
        bias_sigma = min(float(v) for v in reference["bias_std"])
        bias_worst = max(abs(p - float(q)) for p, q in zip(r.bias, reference["bias"]))
        print("live vs offline: largest |bias_live - bias_offline| %.3g rad/s (sigma %.3g)" % (bias_worst, bias_sigma))
        self.assertLessEqual(bias_worst, 0.01 * bias_sigma)
        for a in AXES:
            offline = util.load_yaml(os.path.join(self.tmp, a + ".yaml"))
            for model in ("scale_factor", "drift"):
                live_k, off_k = live_axes[a][model], offline[model]
                values = [live_k["mean"] - off_k["mean"]]
                values += [p - q for p, q in zip(live_k["cos"] + live_k["sin"], off_k["cos"] + off_k["sin"])]
                print("live vs offline: axis %s %s largest difference %.3g" % (a, model, max(map(abs, values))))
                self.assertLessEqual(max(map(abs, values)), 1e-9 if model == "scale_factor" else 1e-12, a)
        self.assertTrue(all(math.isfinite(v) for v in m_live))


if __name__ == "__main__":
    rospy.init_node("triad_calibration_live_test")
    rostest.rosrun("hrg_gyro", "triad_calibration_live", TriadCalibrationLive)
