#!/usr/bin/env python3
"""Each calibration method live on its matching profile (separate nodes, sim time): the calibrator
finishes by itself, accepts, writes the parameter file and reloads the processor; the estimates
show what each method is known to get right (and, for constant rate, its known drift leak). The field
method commands its own virtual rotation: the driver must have executed the calibrator's plan, a
calibrator interrupted mid-plan must stop it, a run that sees another node's command must abort with
nothing written, and the rate a killed calibrator leaves in force must be flagged by the processor.
With glitched stamps (one channel sample and one table record far ahead, one of each far back), the
constant-rate run is accepted as the clean session calibrated offline, each glitch dropped and
counted."""
import glob
import os
import signal
import subprocess
import sys
import tempfile
import unittest
from xmlrpc.client import ServerProxy

import rosbag
import rosgraph
import rosnode
import rospy
import rostest
import yaml
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from hrg_gyro.msg import CalibrationResult, GroundTruth, GyroOutput, ModelInfo, PrecessionCommand, PrecessionState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

# The effective (injected) K harmonics of the shipped gyro seen without P, from the exact model
# (hrg_session prints them): sin 2th and cos 4th are the large ones.
K_SIN2 = 7.679226e-04
K_COS4 = 1.151120e-03
# The resonator's intrinsic 2 theta terms: what is left of 2 theta once P removes the pickoff part.
INTRINSIC_COS2, INTRINSIC_SIN2 = -2.0e-4, 1.5e-4
# The averaged resonator of config/scenarios/resonator_*.yaml: its exact settled D0 through the
# pickoffs (computeEffectiveModel, printed by FieldCalibration.RecoversTheInjectedDriftAndGainOnAStillGyro)
# and the virtual rate's realised gain there measured (1.0035038 +- 7e-8; 1 + the drive's 3e-3 and the
# loops' share).
FIELD_D0 = 9.9733e-06
FIELD_GAIN = 1.0035038


# The keys of config/calibrator.yaml that hrg_bag calibrate --config reads (the others are the node's).
CALIBRATION_KEYS = ("scale_factor_orders", "drift_orders", "bins", "window", "window_span", "group_tolerance",
                    "auto_finish_idle", "backward_reset", "forward_jump", "jump_persist", "bias_trend_order", "plateau",
                    "gates", "thermal", "table_clock", "field")


def clean_offline_report(scenario, prior, method, turntable_records):
    """The same scenario, without glitches, simulated and calibrated by hrg_bag on the part of the
    session the live calibrator saw (it finishes by itself at rest, before the scenario's end: its
    first `turntable_records` table records and the channels up to the last of them): its report."""
    hrg_bag = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                      universal_newlines=True).strip()
    work = tempfile.mkdtemp(prefix="hrg_clean_")
    full, bag = os.path.join(work, "full.bag"), os.path.join(work, "clean.bag")
    report = os.path.join(work, "clean.report.yaml")
    subprocess.run([hrg_bag, "simulate", "--scenario", scenario, "--out", full], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=600)
    with rosbag.Bag(full) as b:
        stamps = [m.header.stamp for _, m, _ in b.read_messages(topics=["/turntable/state"])]
        end = stamps[turntable_records - 1]
        with rosbag.Bag(bag, "w") as out:
            for topic, m, t in b.read_messages():
                if t <= end:
                    out.write(topic, m, t)
    # The calibrator's settings as the live calibrator has them (its node-only keys left out).
    settings = {k: v for k, v in util.load_yaml(os.path.join(os.path.dirname(prior), "calibrator.yaml")).items()
                if k in CALIBRATION_KEYS}
    config = os.path.join(work, "settings.yaml")
    with open(config, "w") as f:
        yaml.safe_dump(settings, f)
    subprocess.run([hrg_bag, "calibrate", bag, "--method", method, "--params", prior, "--config", config,
                    "--report", report, "--out", os.path.join(work, "clean.yaml")],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=600)
    return util.load_yaml(report)


def coefficient(estimate, kind, order):
    i = list(estimate.orders).index(order)
    return getattr(estimate, kind)[i], getattr(estimate, kind + "_std")[i]


class LiveCalibration(unittest.TestCase):
    """What every case shares: the calibrator's results, the processor's model, the driver's precession
    state and the calibrator's diagnostics, listened to from the start."""
    listens_to_truth = False

    def setUp(self):
        self.results = util.Latest("/calibrator/result", CalibrationResult, keep_all=True)
        self.model = util.Latest("/processor/model", ModelInfo, keep_all=True)
        self.precession = util.Latest("/precession/state", PrecessionState)
        # The calibrator's counters go on while it works through its queues after the driver is done.
        self.calibrator = util.Diagnostic("calibrator: calibration", ("wave samples", "turntable states", "runs"))
        self.run_keys = set()  # keys of the calibrator's status while a run was in progress
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        if self.listens_to_truth:
            # The field tests' driver waits for this subscriber (~wait_for_subscribers/truth): their run
            # lasts seconds of wall time, and everything above must listen before it starts.
            self.truth = util.Latest("/truth", GroundTruth)

    def on_diagnostics(self, msg):
        for s in msg.status:
            values = {kv.key: kv.value for kv in s.values}
            if s.name.endswith(": calibration") and "progress" in values:
                self.run_keys.update(values)

    def final_result(self, count):
        # However long the session takes in wall time: fails only when it stops moving.
        util.wait_for(lambda: self.results.count >= count,
                      lambda: "%d calibration result(s) (calibrator: %s %r)" %
                      (count, self.calibrator.message, self.calibrator.values))
        return self.results.all[count - 1]

    def check_written(self, r, method):
        self.assertEqual(r.method, method)
        self.assertTrue(r.accepted, r.reason + " / " + "; ".join(g.message for g in r.gates if not g.passed))
        self.assertTrue(r.written, r.reason)
        util.wait_for(lambda: self.model.msg and self.model.msg.calibration_method == method,
                      "the processor to reload the %s result" % method)
        written = util.load_yaml(rospy.get_param("~parameter_file"))
        self.assertEqual(written["calibration"]["method"], method)


class ConstantRate(LiveCalibration):
    """Accepted and written; cos 4 theta unbiased, the mean K carrying the known drift leak."""

    def test_constant_rate(self):
        r = self.final_result(1)
        self.check_written(r, "constant_rate")
        k = r.scale_factor[0]
        c4, _ = coefficient(k, "cos", 4)
        self.assertAlmostEqual(c4, K_COS4, delta=5e-6)  # D has no 4 theta term: unbiased
        self.assertAlmostEqual(k.mean, -0.56, delta=1e-3)  # D(theta_dwell) vs mean D leaks here


class ConstantRateGlitched(LiveCalibration):
    """Each glitch dropped and counted, no restart, and the estimates those of the clean session offline."""

    def test_constant_rate_glitched(self):
        statuses = {}

        def on_diagnostics(msg):
            for s in msg.status:
                statuses[s.name] = {kv.key: kv.value for kv in s.values}
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=100)
        r = self.final_result(1)
        self.check_written(r, "constant_rate")
        # Each glitch was dropped and counted, and the run never restarted.
        report_path = [p for p in glob.glob(os.path.join(os.path.dirname(rospy.get_param("~parameter_file")),
                                                         "*.report.yaml"))][0]
        report = util.load_yaml(report_path)
        self.assertEqual(report["turntable_rejected"]["stamp_jump"], 2, report["turntable_rejected"])
        self.assertEqual(report["restarts"], 0)
        util.wait_for(lambda: any("stamp jumps dropped" in v for v in statuses.values()), "the processor's input diagnostics")
        processor = [v for v in statuses.values() if "stamp jumps dropped" in v][0]
        self.assertEqual(int(processor["stamp jumps dropped"]), 2)
        self.assertEqual(int(processor["resets (time went backwards)"]), 0)
        # The same estimates as the clean session's, offline: within a tenth of their sigmas.
        clean = clean_offline_report(rospy.get_param("~scenario"), rospy.get_param("~prior_file"),
                                     "constant_rate", report["turntable_records"])["scale_factor"][0]
        k = r.scale_factor[0]
        worst = abs(k.mean - clean["mean"]) / k.mean_std
        for kind in ("cos", "sin"):
            for value, std, other in zip(getattr(k, kind), getattr(k, kind + "_std"), clean[kind]):
                worst = max(worst, abs(value - other) / std)
        print("glitched live against clean offline: largest difference %.3f sigma" % worst)
        self.assertLess(worst, 0.1)


class Step(LiveCalibration):
    """The step method's cos 4 and sin 2 theta terms of K and its D0."""

    def test_step(self):
        r = self.final_result(1)
        self.check_written(r, "step")
        k = r.scale_factor[0]
        c4, c4s = coefficient(k, "cos", 4)
        s2, s2s = coefficient(k, "sin", 2)
        self.assertLess(abs(c4 - K_COS4), max(6 * c4s, 2e-6))
        self.assertLess(abs(s2 - K_SIN2), max(6 * s2s, 2e-6))
        self.assertAlmostEqual(r.drift[0].mean, 1e-5, delta=3e-7)


class TwoStage(LiveCalibration):
    """The correction matrix first (every sweep sample paired), then the dual rate through the new P."""

    def test_two_stage(self):
        p = self.final_result(1)
        self.check_written(p, "correction_matrix")
        self.assertTrue(any(abs(x) > 1e-4 for x in p.correction))
        # Every sample of the sweep paired (24 angles x 3 quadratures x 2 phases x 0.05 s at
        # 200 Hz), also when its last raw channels arrive after truth has left the sweep.
        self.assertEqual(p.samples, 1440)
        r = self.final_result(2)
        self.check_written(r, "dual_rate")
        self.assertEqual(list(r.correction), list(p.correction))  # measured through the new P
        k = r.scale_factor[0]
        c2, c2s = coefficient(k, "cos", 2)
        s2, s2s = coefficient(k, "sin", 2)
        c4, _ = coefficient(k, "cos", 4)
        # The pickoff's 2 theta signature is gone; the resonator's own remains.
        self.assertLess(abs(c2 - INTRINSIC_COS2), max(6 * c2s, 3e-6))
        self.assertLess(abs(s2 - INTRINSIC_SIN2), max(6 * s2s, 3e-6))
        self.assertAlmostEqual(c4, K_COS4, delta=2e-5)  # the 4 theta term stays in K


class Field(LiveCalibration):
    """D0 and the virtual rate's gain against the exact figures; the driver executed the plan."""
    listens_to_truth = True

    def test_field(self):
        r = self.final_result(1)
        # The figures the gates judged, printed before any assertion: a refused run shows its margins.
        for g in r.gates:
            print("field live gate %s: %s %.4g (limit %.4g)" % (g.name, "passed" if g.passed else "FAILED",
                                                               g.value, g.limit))
        self.check_written(r, "field")
        self.assertEqual(len(r.scale_factor), 0, "K is not estimated by a field calibration")
        written, prior = util.load_yaml(rospy.get_param("~parameter_file")), util.load_yaml(
            rospy.get_param("~prior_file"))
        self.assertEqual(written["scale_factor"], prior["scale_factor"], "K kept from the prior")
        d = r.drift[0]
        print("field live: D0 %.6g +- %.2g rad/s (exact %.6g)" % (d.mean, d.mean_std, FIELD_D0))
        self.assertLess(abs(d.mean - FIELD_D0), 5 * d.mean_std + 2e-8)
        self.assertAlmostEqual(written["drift"]["mean"], d.mean, delta=1e-12)
        gain = [g for g in r.gates if g.name == "virtual_rate_gain"]
        self.assertEqual(len(gain), 1)
        print("field live: virtual rate gain error %.7f (exact %.7f)" % (gain[0].value, abs(FIELD_GAIN - 1.0)))
        self.assertLess(abs(gain[0].value - abs(FIELD_GAIN - 1.0)), 1e-5)
        # The driver executed the calibrator's plan: 0, +0.2, -0.2, 0 rad/s.
        util.wait_for(lambda: self.precession.msg is not None and self.precession.msg.commands >= 4,
                      "the driver to have executed the four planned commands")
        self.assertEqual(self.precession.msg.commands, 4)
        self.assertEqual(self.precession.msg.rate, 0.0)
        # The run's diagnostics count the stream it reads: precession states, not turntable records.
        self.assertIn("precession states", self.run_keys)
        self.assertIn("precession dropped (bad rate)", self.run_keys)
        self.assertIn("without precession state", self.run_keys)
        self.assertEqual([k for k in self.run_keys if "turntable" in k], [])


class FieldInterrupted(LiveCalibration):
    """SIGINT mid-plan: the calibrator commands rate 0 before it exits; nothing written."""
    listens_to_truth = True

    def test_field_interrupted(self):
        # SIGINT while the wave turns at the plan's +0.2 rad/s: the calibrator commands 0 before it exits.
        with open(rospy.get_param("~parameter_file")) as f:
            before = f.read()
        util.wait_for(lambda: self.precession.msg is not None and self.precession.msg.commands == 2 and
                      self.precession.msg.rate > 0.0, "the first segment of the virtual rotation")
        pid = ServerProxy(rosgraph.Master("/calibration_method_test").lookupNode("/calibrator")).getPid("/test")[2]
        os.kill(pid, signal.SIGINT)
        util.wait_for(lambda: self.precession.msg.commands == 3, "the calibrator's stop command")
        self.assertEqual(self.precession.msg.rate, 0.0, "the wave left turning")
        util.wait_for(lambda: not rosnode.rosnode_ping("/calibrator", max_count=1), "the calibrator to exit")
        self.assertEqual(self.results.count, 0, "no result from an interrupted run")
        with open(rospy.get_param("~parameter_file")) as f:
            self.assertEqual(f.read(), before, "the parameter file untouched")


class FieldForeign(LiveCalibration):
    """Another node's command aborts the run at once, nothing written, the wave stopped."""
    listens_to_truth = True

    def test_field_foreign(self):
        # While the plan turns the wave (+0.2 rad/s), this node -- no calibrator -- commands rate 0.
        with open(rospy.get_param("~parameter_file")) as f:
            before = f.read()
        report = os.path.splitext(rospy.get_param("~parameter_file"))[0] + ".field.report.yaml"
        diagnostics = util.Latest("/diagnostics", DiagnosticArray, keep_all=True)
        pub = rospy.Publisher("/command/precession", PrecessionCommand, queue_size=10)
        util.wait_for(lambda: self.precession.msg is not None and self.precession.msg.commands == 2 and
                      self.precession.msg.rate > 0.0 and pub.get_num_connections() >= 1, "the first segment of the virtual rotation, the driver listening")
        self.assertEqual(self.precession.msg.source, "/calibrator")
        msg = PrecessionCommand()
        msg.rate = 0.0
        pub.publish(msg)
        r = self.final_result(1)
        me = rospy.get_name()
        self.assertFalse(r.accepted)
        self.assertFalse(r.written)
        self.assertEqual(r.method, "field")
        self.assertTrue(r.reason.startswith("precession_command: "), r.reason)
        self.assertIn("command from %s, not from this calibrator (/calibrator)" % me, r.reason)
        self.assertEqual([(g.name, g.passed) for g in r.gates], [("precession_command", False)])
        # Aborted at once: the stranger's command was the driver's third, and the calibrator's stop
        # (rate 0, the plan had the wave turning) its fourth and last.
        util.wait_for(lambda: self.precession.msg.commands == 4, "the calibrator's stop command")
        self.assertEqual(self.precession.msg.rate, 0.0)
        self.assertEqual(self.precession.msg.source, "/calibrator")

        def aborted():
            for d in list(diagnostics.all):
                for s in d.status:
                    if s.name.endswith("calibrator: calibration") and "aborted, nothing written" in s.message:
                        return s
            return None
        status = util.wait_for(aborted, "the calibrator's diagnostic saying the run was aborted")
        self.assertEqual(status.level, DiagnosticStatus.WARN)
        self.assertIn(me, status.message)
        with open(rospy.get_param("~parameter_file")) as f:
            self.assertEqual(f.read(), before, "the parameter file untouched")
        self.assertFalse(os.path.exists(report), "no report of an aborted run")
        self.assertEqual(self.results.count, 1)


class FieldKilled(LiveCalibration):
    """SIGKILL mid-plan: the processor flags every output of the turning wave and names the commander."""
    listens_to_truth = True

    def test_field_killed(self):
        # SIGKILL while the plan turns the wave at +0.2 rad/s: the calibrator cannot stop it.
        with open(rospy.get_param("~parameter_file")) as f:
            before = f.read()
        outputs = util.Latest("/output", GyroOutput, keep_all=True)
        diagnostics = util.Latest("/diagnostics", DiagnosticArray, keep_all=True)
        util.wait_for(lambda: self.precession.msg is not None and self.precession.msg.commands == 2 and
                      self.precession.msg.rate > 0.0, "the first segment of the virtual rotation")
        pid = ServerProxy(rosgraph.Master("/calibration_method_test").lookupNode("/calibrator")).getPid("/test")[2]
        os.kill(pid, signal.SIGKILL)
        util.wait_for(lambda: not rosnode.rosnode_ping("/calibrator", max_count=1), "the calibrator to die")
        killed = self.precession.msg.header.stamp.to_nsec()
        # 3 s of simulated time with the rate left in force, out of the processor.
        util.wait_for(lambda: outputs.msg is not None and outputs.msg.header.stamp.to_nsec() > killed + 3000000000, "3 s of outputs after the kill")
        self.assertEqual((self.precession.msg.rate, self.precession.msg.commands), (0.2, 2), "left in force")
        after = [o for o in list(outputs.all) if o.header.stamp.to_nsec() > killed]
        self.assertGreater(len(after), 300)
        unflagged = [o.header.stamp.to_nsec() for o in after if not o.flags & GyroOutput.FLAG_PRECESSING]
        self.assertEqual(unflagged, [], "outputs of the turning wave not flagged")
        # ... and they read as a body rate of 0.2 / K0 (K0 -0.56): what a filter must not fuse.
        self.assertGreater(min(abs(o.rate) for o in after), 0.3)

        def warned():
            for d in list(diagnostics.all):
                for s in d.status:
                    if s.name.endswith("processor: precession") and s.level == DiagnosticStatus.WARN and \
                            "0.2 rad/s in force, commanded by /calibrator" in s.message:
                        return s
            return None
        util.wait_for(warned, "the processor's precession WARN naming /calibrator")
        self.assertEqual(self.results.count, 0, "no result from a killed run")
        with open(rospy.get_param("~parameter_file")) as f:
            self.assertEqual(f.read(), before, "the parameter file untouched")


# The case a .test file names (~case), each one test of its own class.
CASES = {"constant_rate": ConstantRate, "constant_rate_glitched": ConstantRateGlitched, "step": Step,
         "two_stage": TwoStage, "field": Field, "field_interrupted": FieldInterrupted, "field_foreign": FieldForeign,
         "field_killed": FieldKilled}


if __name__ == "__main__":
    rospy.init_node("calibration_method_test")
    case = rospy.get_param("~case")
    if case not in CASES:
        raise SystemExit("calibration_method_test: unknown ~case %r (one of %s)" % (case, ", ".join(sorted(CASES))))
    rostest.rosrun("hrg_gyro", "calibration_method_" + case, CASES[case])
