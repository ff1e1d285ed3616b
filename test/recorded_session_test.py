#!/usr/bin/env python3
"""Recorded sessions, the way a test engineer runs them: record.launch records a simulated session
(with the live processor's outputs), playback.launch replays the bag with --clock through a fresh
processor, and `hrg_bag process` runs the same bag offline. The replayed and the offline outputs
must equal the live ones bit for bit; a looping playback must reset the processor and restart the
calibrator instead of integrating across the jump back. The same holds for a gyro whose precession
loop turns the wave: the outputs' PRECESSING flags live, replayed and offline are the same.

Each launch runs on a private master (its own port), as a user would run it from a shell."""
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

OUTPUT_FIELDS = ("dt", "dtheta", "dalpha", "dalpha_earth_fixed", "alpha", "rate", "theta_mid", "frequency",
                 "scale_factor", "drift", "rejected_before", "flags")
HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
WAVE_FIELDS = ("theta", "amplitude", "quadrature", "phase", "energy", "quadrature_product", "phase_error",
               "frequency", "temperature")


def roslaunch(args, bags=(), stop_when=None, times=1):
    """Runs `roslaunch hrg_gyro ARGS` on a private master until it ends; with stop_when (a text of
    its log), interrupts it once the log shows it `times` times (Ctrl-C, so the recorders close
    their bags).
    However long it takes in wall time: it fails only when neither its log nor the bags being
    written (`bags`, as BAG.active) grew for util.STALL s. Returns (exit code, log text)."""
    port = random.randint(20000, 40000)
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    log = tempfile.NamedTemporaryFile("w+", prefix="hrg_roslaunch.", suffix=".log")
    proc = subprocess.Popen(["roslaunch", "-p", str(port), "hrg_gyro"] + args, env=env, stdout=log,
                            stderr=subprocess.STDOUT, universal_newlines=True)

    def size(path):
        try:
            return os.path.getsize(path)
        except OSError:
            return -1

    def text():
        with open(log.name) as f:
            return f.read()
    source = util.watch(lambda: (size(log.name),) + tuple(size(b + ".active") for b in bags) +
                        tuple(size(b) for b in bags))
    try:
        if stop_when is not None:
            util.wait_for(lambda: text().count(stop_when) >= times or proc.poll() is not None,
                          lambda: "'%s' %d times in the log of roslaunch %s:\n%s" %
                          (stop_when, times, " ".join(args), text()[-3000:]))
            proc.send_signal(signal.SIGINT)
        util.wait_for(lambda: proc.poll() is not None,
                      lambda: "roslaunch %s to end:\n%s" % (" ".join(args), text()[-3000:]))
    except AssertionError:
        proc.kill()
        proc.wait()
        raise
    finally:
        util.unwatch(source)
    out = text()
    log.close()
    return proc.returncode, out


def same(a, b):
    return a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))


def by_stamp(bag_path, topic):
    with rosbag.Bag(bag_path) as bag:
        return {m.header.stamp.to_nsec(): m for _, m, _ in bag.read_messages(topics=[topic])}


class RecordedSession(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "recorded")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.params = os.path.join(cls.work, "params.yaml")
        shutil.copy(rospy.get_param("~parameter_file"), cls.params)
        cls.live = os.path.join(cls.work, "live.bag")
        cls.replay = os.path.join(cls.work, "replay.bag")
        cls.offline = os.path.join(cls.work, "offline.bag")
        scenario = rospy.get_param("~scenario")
        # Real time: rosbag record subscribes with a queue of 100 and drops beyond it.
        code, cls.record_log = roslaunch(["record.launch", "bag:=" + cls.live, "simulate:=true",
                                          "record_outputs:=true", "time_scale:=1.0", "scenario:=" + scenario,
                                          "parameter_file:=" + cls.params], bags=[cls.live])
        code, cls.replay_log = roslaunch(["playback.launch", "bag:=" + cls.live, "parameter_file:=" + cls.params,
                                          "record_to:=" + cls.replay], bags=[cls.replay])
        cls.process = subprocess.run([HRG_BAG, "process", cls.live, "--params", cls.params,
                                      "--out", cls.offline], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     universal_newlines=True)

    def test_1_the_recording_is_complete(self):
        self.assertTrue(os.path.exists(self.live), self.record_log[-3000:])
        channels = by_stamp(self.live, "/channels")
        seqs = sorted(m.header.seq for m in channels.values())
        # 33 s of scenario at 200 Hz, every sample recorded
        self.assertGreater(len(seqs), 6000)
        self.assertEqual(seqs, list(range(seqs[0], seqs[0] + len(seqs))), "samples lost in the recording")
        for topic in ("/turntable/state", "/truth", "/output", "/wave"):
            self.assertGreater(len(by_stamp(self.live, topic)), 0.99 * len(seqs), topic)
        info = subprocess.run([HRG_BAG, "info", self.live], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True)
        self.assertEqual(info.returncode, 0, info.stdout)

    def assert_outputs_equal(self, reference, candidate, what, min_fraction):
        common = sorted(set(reference) & set(candidate))
        print("%s: %d of the %d live outputs; missing: %d of the first 100, %d of the last 400" % (
            what, len(common), len(reference), sum(1 for s in sorted(reference)[:100] if s not in candidate),
            sum(1 for s in sorted(reference)[-400:] if s not in candidate)))
        self.assertGreaterEqual(len(common), min_fraction * len(reference),
                                "%s: only %d of %d live outputs" % (what, len(common), len(reference)))
        for stamp in common:
            for f in OUTPUT_FIELDS:
                a, b = getattr(reference[stamp], f), getattr(candidate[stamp], f)
                self.assertTrue(same(a, b), "%s differs at %d in %s: %r vs %r" % (what, stamp, f, a, b))
        return len(common)

    def test_2_replay_gives_the_live_outputs_bit_for_bit(self):
        self.assertTrue(os.path.exists(self.replay), self.replay_log[-3000:])
        live = by_stamp(self.live, "/output")
        replay = by_stamp(self.replay, "/output")
        # the replayed processor ran on sim time from the bag's clock: same stamps, same numbers, every one
        # (the launch ends once the processor is through the bag: ~shutdown_when_idle)
        self.assert_outputs_equal(live, replay, "replay", 1.0)

    def test_3_hrg_bag_process_gives_the_live_outputs_bit_for_bit(self):
        self.assertEqual(self.process.returncode, 0, self.process.stdout)
        live = by_stamp(self.live, "/output")
        offline = by_stamp(self.offline, "/output")
        n = self.assert_outputs_equal(live, offline, "hrg_bag process", 1.0)
        live_wave, offline_wave = by_stamp(self.live, "/wave"), by_stamp(self.offline, "/wave")
        for stamp in live_wave:
            for f in WAVE_FIELDS:
                a, b = getattr(live_wave[stamp], f), getattr(offline_wave[stamp], f)
                self.assertTrue(same(a, b), "wave differs at %d in %s: %r vs %r" % (stamp, f, a, b))
        self.assertGreater(n, 6000)

    def test_4_a_looping_playback_resets_instead_of_integrating_across(self):
        looped = os.path.join(self.work, "looped.bag")
        params = os.path.join(self.work, "params_loop.yaml")
        shutil.copy(self.params, params)
        # Until the third pass has begun (the calibrator's restart is logged after the processor's
        # reset): a whole pass, at least 38 s / 8 of wall time, lies between, so the diagnostics of
        # the first reset are in the bag however slowly the host plays it. The calibrator runs (its
        # dual-rate data stay incomplete).
        code, log = roslaunch(["playback.launch", "bag:=" + self.live, "parameter_file:=" + params, "loop:=true",
                               "rate:=8", "calibrate:=true", "record_to:=" + looped,
                               "output:=screen"], bags=[looped], stop_when="calibrator: time went back", times=2)
        self.assertTrue(os.path.exists(looped), log[-3000:])
        outputs = list(by_stamp(looped, "/output").values())
        self.assertGreater(len(outputs), 1000, log[-3000:])
        # at most one sample of a 0.2 rad/s table: nothing like the 38 s jump back
        self.assertLess(max(abs(o.dalpha) for o in outputs), 0.01)
        self.assertTrue(all(math.isfinite(o.dalpha) and math.isfinite(o.alpha) for o in outputs))
        resets, restarts = 0, 0
        with rosbag.Bag(looped) as bag:
            for _, msg, _ in bag.read_messages(topics=["/diagnostics"]):
                for status in msg.status:
                    for kv in status.values:
                        if kv.key == "resets (time went backwards)":
                            resets = max(resets, int(kv.value))
                        if kv.key == "restarts (time went backwards)":
                            restarts = max(restarts, int(kv.value))
        self.assertGreaterEqual(resets, 1, "the processor must reset at the loop")
        self.assertGreaterEqual(restarts, 1, "the calibrator must restart its run at the loop")
        self.assertIn("time went backwards", log)

    def test_5_the_precession_flags_are_the_live_ones_replayed_and_offline(self):
        # A gyro with a precession loop whose schedule turns the wave (0.3 rad/s from 4 to 7 s, -0.3 from
        # 12 to 15 s, 0.5 rad/s for 1 ms at 9.0005 s): the live processor flags the outputs PRECESSING
        # from precession/state; the replay (which plays the state with the channels) and hrg_bag process
        # (which reads it from the bag) must give every output, flags included, bit for bit.
        scenario = os.path.join(os.path.dirname(rospy.get_param("~scenario")), "precession_recorded.yaml")
        live, replay, offline = (os.path.join(self.work, n) for n in ("precession_live.bag",
                                                                       "precession_replay.bag",
                                                                       "precession_offline.bag"))
        code, log = roslaunch(["record.launch", "bag:=" + live, "simulate:=true", "record_outputs:=true",
                               "time_scale:=1.0", "scenario:=" + scenario, "parameter_file:=" + self.params],
                              bags=[live])
        self.assertTrue(os.path.exists(live), log[-3000:])
        code, replay_log = roslaunch(["playback.launch", "bag:=" + live, "parameter_file:=" + self.params,
                                      "record_to:=" + replay], bags=[replay])
        process = subprocess.run([HRG_BAG, "process", live, "--params", self.params, "--out", offline],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                 timeout=120)
        self.assertEqual(process.returncode, 0, process.stdout)
        self.assertIn("outputs flagged PRECESSING", process.stdout)
        live_out = by_stamp(live, "/output")
        states = by_stamp(live, "/precession/state")
        self.assertGreater(len(states), 0.99 * len(live_out))
        start = 1.0  # the scenario's start_time: stamps are 1 s ahead of its schedule's times
        flagged = sorted(t * 1e-9 - start for t, o in live_out.items() if o.flags & 16)
        # 3 s at 200 Hz twice (and a sample at either switch), and the 1 ms command's one sample.
        self.assertGreater(len(flagged), 2 * 590)
        self.assertLess(len(flagged), 2 * 610)
        self.assertTrue(all(3.99 < t < 7.02 or 11.99 < t < 15.02 or abs(t - 9.0025) < 1e-6 for t in flagged), flagged)
        pulse = [t for t in flagged if 8.0 < t < 11.0]
        self.assertEqual(len(pulse), 1, "the 1 ms command flags exactly its own sample: %s" % pulse)
        self.assertTrue(os.path.exists(replay), replay_log[-3000:])
        self.assert_outputs_equal(live_out, by_stamp(replay, "/output"), "precession replay", 1.0)
        self.assert_outputs_equal(live_out, by_stamp(offline, "/output"), "precession hrg_bag process", 1.0)


if __name__ == "__main__":
    rospy.init_node("recorded_session_test")
    rostest.rosrun("hrg_gyro", "recorded_session", RecordedSession)
