#!/usr/bin/env python3
"""The hrg_bag command line, as a lab user runs it: every subcommand on small generated bags, the
documented chain simulate -> info -> calibrate -> process on config/scenarios/dual_rate.yaml, and
bad bags (missing, truncated/unindexed, wrong types, no channels topic) answered by a clear error
and a non-zero exit, never a crash. Needs no master; run as a rostest for the package environment."""
import contextlib
import csv
import errno
import filecmp
import math
import os
import re
import shutil
import subprocess
import unittest

import rosbag
import rospy
import rostest
import yaml
from hrg_gyro.msg import ChannelAmplitudes, TurntableState
from std_msgs.msg import String


HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()


HRG_SESSION = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_session"],
                                      universal_newlines=True).strip()


def run(tool, *args, timeout=600, env=None):
    p = subprocess.run([tool] + list(args), stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=timeout, env=env)
    return p.returncode, p.stdout, p.stderr


def hrg_bag(*args, timeout=600, env=None):
    return run(HRG_BAG, *args, timeout=timeout, env=env)


def snapshot(directory):
    """Every name in `directory` with its content: what a refused or failed write must not change."""
    state = {}
    for name in sorted(os.listdir(directory)):
        path = os.path.join(directory, name)
        if os.path.islink(path):
            state[name] = ("link", os.readlink(path))
        elif os.path.isdir(path):
            state[name] = ("dir",)
        else:
            with open(path, "rb") as f:
                state[name] = ("file", f.read())
    return state


def fill(directory, leave_bytes):
    """Fills the file system of `directory` until at most `leave_bytes` are free; returns the filler."""
    filler = os.path.join(directory, "filler")
    st = os.statvfs(directory)
    free = st.f_bavail * st.f_frsize
    with open(filler, "ab") as f:
        try:
            f.write(b"\0" * max(0, free - leave_bytes))
            f.flush()
            os.fsync(f.fileno())
        except OSError as e:
            if e.errno != errno.ENOSPC:
                raise
    return filler


@contextlib.contextmanager
def small_disk(path, size):
    """A tmpfs of `size` mounted at `path` (made), unmounted afterwards; None when it cannot be mounted
    (mounting needs root)."""
    os.makedirs(path)
    mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + size, "tmpfs", path], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True)
    if mount.returncode != 0:
        yield None, "cannot mount a %s tmpfs to fill (needs root): %s" % (size, mount.stdout.strip())
        return
    try:
        yield path, ""
    finally:
        subprocess.run(["umount", path])


class HrgBagCli(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "hrg_bag_cli")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.pkg = rospy.get_param("~package_dir")
        cls.params = os.path.join(cls.pkg, "config", "params_uncalibrated.yaml")
        cls.short = os.path.join(cls.work, "short.bag")
        code, out, err = hrg_bag("simulate", "--scenario", os.path.join(cls.pkg, "test/scenarios/short_session.yaml"),
                                 "--out", cls.short)
        assert code == 0, err

    def path(self, name):
        return os.path.join(self.work, name)

    def triad_bag(self):
        """A short triad session (test/scenarios/triad_short.yaml), simulated once for the tests that need it."""
        bag = self.path("triad_session.bag")
        if not os.path.exists(bag):
            code, _, err = hrg_bag("simulate", "--scenario", os.path.join(self.pkg, "test/scenarios/triad_short.yaml"),
                                   "--out", bag)
            self.assertEqual(code, 0, err)
        return bag

    def triad_priors(self, d):
        """The prior triad file and each axis's prior parameter file in `d`: (triad, {axis: file})."""
        triad = os.path.join(d, "triad.yaml")
        shutil.copy(os.path.join(self.pkg, "config/triad.yaml"), triad)
        axes = {}
        for a in "xyz":
            axes[a] = os.path.join(d, a + ".yaml")
            shutil.copy(self.params, axes[a])
        return triad, axes

    def triad_calibrate(self, bag, triad, axes, *extra):
        args = ["calibrate", bag, "--method", "triad", "--config",
                os.path.join(self.pkg, "test/scenarios/triad_short_calibration.yaml"), "--triad", triad]
        for a in "xyz":
            args += ["--axis-params", "%s=%s" % (a, axes[a])]
        return args + list(extra)

    def assertFails(self, result, code, *fragments):
        self.assertEqual(result[0], code, result)
        for f in fragments:
            self.assertIn(f, result[2])
        self.assertNotIn("terminate called", result[2])

    def assertRefused(self, result, option, why, args):
        """Bad usage: exit 2 (not a signal, not 0), stderr names the option and the reason."""
        code, _, err = result
        self.assertEqual(code, 2, "%s -> exit %d (negative: killed by a signal)\n%s" % (args, code, err))
        self.assertIn(option, err, args)
        self.assertIn(why, err, args)
        self.assertNotIn("terminate called", err, args)

    def test_help_for_the_tool_and_every_subcommand(self):
        code, out, _ = hrg_bag("--help")
        self.assertEqual(code, 0)
        for sub in ("simulate", "info", "process", "calibrate", "allan"):
            self.assertIn(sub, out)
            code, out_sub, _ = hrg_bag(sub, "--help")
            self.assertEqual(code, 0, sub)
            self.assertIn("usage: hrg_bag " + sub, out_sub)
        self.assertFails(hrg_bag("frobnicate"), 2, "frobnicate")
        self.assertFails(hrg_bag("process", self.short, "--params", self.params, "--out", self.path("x.bag"),
                                 "--bogus", "1"), 2, "--bogus")

    def test_simulate_writes_the_three_streams_deterministically(self):
        with rosbag.Bag(self.short) as bag:
            info = bag.get_type_and_topic_info().topics
        self.assertEqual(info["/channels"].msg_type, "hrg_gyro/ChannelAmplitudes")
        self.assertEqual(info["/turntable/state"].msg_type, "hrg_gyro/TurntableState")
        self.assertEqual(info["/truth"].msg_type, "hrg_gyro/GroundTruth")
        n = info["/channels"].message_count
        self.assertEqual(info["/turntable/state"].message_count, n)
        self.assertEqual(info["/truth"].message_count, n)
        self.assertGreater(n, 6000)
        scenario = os.path.join(self.pkg, "test/scenarios/short_session.yaml")
        self.assertEqual(hrg_bag("simulate", "--scenario", scenario, "--out", self.path("again.bag"))[0], 0)
        self.assertTrue(filecmp.cmp(self.short, self.path("again.bag"), shallow=False), "same seed, same bag")
        self.assertEqual(hrg_bag("simulate", "--scenario", scenario, "--out", self.path("seed7.bag"),
                                 "--seed", "7")[0], 0)
        self.assertFalse(filecmp.cmp(self.short, self.path("seed7.bag"), shallow=False), "--seed changes the noise")
        self.assertFails(hrg_bag("simulate", "--scenario", self.path("nope.yaml"), "--out", self.path("n.bag")), 2,
                         "nope.yaml")

    def test_simulate_writes_the_controller_count_and_clock(self):
        # The table logged at 100 Hz on its own clock (0.1 s ahead, 2 ms of jitter), 5 % of its
        # records and of the channel samples lost: header.seq is the controller's count (the sample
        # index for /channels), so each loss leaves a gap; the bag time is when the record was made.
        with open(os.path.join(self.pkg, "test/scenarios/short_session.yaml")) as f:
            scenario = f.read()
        scenario += ("  log: {rate: 100.0, drop_probability: 0.05, clock: {offset: 0.1, jitter: 0.002}}\n"
                     "channels: {drop_probability: 0.05}\n")
        path, bag_path = self.path("clock.yaml"), self.path("clock.bag")
        with open(path, "w") as f:
            f.write(scenario)
        code, _, err = hrg_bag("simulate", "--scenario", path, "--out", bag_path, "--no-truth")
        self.assertEqual(code, 0, err)
        seqs = {"/channels": [], "/turntable/state": []}
        offsets = []
        with rosbag.Bag(bag_path) as bag:
            for topic, msg, t in bag.read_messages(topics=list(seqs)):
                seqs[topic].append(msg.header.seq)
                if topic == "/turntable/state":
                    offsets.append(msg.header.stamp.to_sec() - t.to_sec())
        for topic, seq in seqs.items():
            steps = [b - a for a, b in zip(seq, seq[1:])]
            self.assertTrue(all(s >= 1 for s in steps), topic)
            lost = sum(s - 1 for s in steps)
            # 5 % of ~3700 records and ~7400 samples: 5 sigma below the expected losses is still > 100.
            self.assertGreater(lost, 100, topic)
            self.assertEqual(seq[0] + len(seq) + lost - 1, seq[-1], topic)
        n = len(offsets)
        mean = sum(offsets) / n
        std = math.sqrt(sum((o - mean) ** 2 for o in offsets) / n)
        # The record's bag time is its true time (rounded to the ns, as its stamp is): the stamps lead
        # by the offset with the jitter's spread, within 5 sigma of their estimates over n records.
        self.assertAlmostEqual(mean, 0.1, delta=5 * 0.002 / math.sqrt(n))
        self.assertAlmostEqual(std, 0.002, delta=5 * 0.002 / math.sqrt(2 * n))

    def test_simulate_writes_the_precession_commands_and_state(self):
        # A gyro with a precession loop (the averaged resonator): the schedule's commands on
        # /command/precession at the carrier period that took each up, as a commanding node sends them,
        # and the loop's state with every channel sample (the rate in force and its integral).
        with open(os.path.join(self.pkg, "test/scenarios/precession_short.yaml")) as f:
            scenario = f.read()
        scenario = scenario.replace("  commands: []", "  commands: [{time: 1.0, rate: 0.4}, {time: 3.0, rate: -0.2}]")
        scenario = scenario.replace("duration: 90.0", "duration: 5.0")
        path, bag_path = self.path("precession.yaml"), self.path("precession.bag")
        with open(path, "w") as f:
            f.write(scenario)
        code, _, err = hrg_bag("simulate", "--scenario", path, "--out", bag_path, "--no-truth")
        self.assertEqual(code, 0, err)
        with rosbag.Bag(bag_path) as bag:
            info = bag.get_type_and_topic_info().topics
            commands = [(t.to_sec(), m) for _, m, t in bag.read_messages(topics=["/command/precession"])]
            states = [m for _, m, _ in bag.read_messages(topics=["/precession/state"])]
        self.assertEqual(info["/command/precession"].msg_type, "hrg_gyro/PrecessionCommand")
        self.assertEqual(info["/precession/state"].msg_type, "hrg_gyro/PrecessionState")
        self.assertEqual(info["/precession/state"].message_count, info["/channels"].message_count)
        self.assertEqual([m.rate for _, m in commands], [0.4, -0.2])
        for (t, m), due in zip(commands, (1.0, 3.0)):
            self.assertAlmostEqual(t, 1.0 + due, delta=1e-6)  # start_time 1.0
            self.assertAlmostEqual(m.header.stamp.to_sec(), t, delta=1e-9)
        last = states[-1]
        self.assertEqual((last.rate, last.commands), (-0.2, 2))
        # At the last sample's centre (4.9975 s): 0.4 rad/s for 2 s, then -0.2 rad/s for 1.9975 s.
        self.assertAlmostEqual(last.angle, 0.4 * 2.0 - 0.2 * 1.9975, delta=1e-9)
        # Who commanded the rate in force: nobody before the first command, then the scenario's schedule.
        self.assertEqual({m.source for m in states if m.commands == 0}, {""})
        self.assertEqual({m.source for m in states if m.commands > 0}, {"schedule"})

    def test_process_flags_the_precessed_outputs_also_from_an_older_bag(self):
        # The loop turns the wave at 0.4 rad/s from 1 s to 3 s: hrg_bag process reads the precession
        # state beside the channels and flags exactly the outputs the documented rule flags (a rate
        # other than 0 at either end of the output's interval, or a commanded angle that moved), which
        # read as about 0.7 rad/s of body rate. A bag recorded before PrecessionState had `source` (its
        # earlier MD5 sum) gives the same flags.
        with open(os.path.join(self.pkg, "test/scenarios/precession_short.yaml")) as f:
            scenario = f.read()
        scenario = scenario.replace("  commands: []", "  commands: [{time: 1.0, rate: 0.4}, {time: 3.0, rate: 0.0}]")
        scenario = scenario.replace("duration: 90.0", "duration: 5.0")
        path, bag_path = self.path("precessed.yaml"), self.path("precessed.bag")
        with open(path, "w") as f:
            f.write(scenario)
        code, _, err = hrg_bag("simulate", "--scenario", path, "--out", bag_path, "--no-truth")
        self.assertEqual(code, 0, err)
        # The same bag with the state in the earlier layout (no `source`).
        import genpy.dynamic
        from hrg_gyro.msg import PrecessionState
        old_text = PrecessionState._full_text.replace("string source", "# (no source)")
        OldState = genpy.dynamic.generate_dynamic("hrg_gyro/PrecessionState", old_text)["hrg_gyro/PrecessionState"]
        self.assertEqual(OldState._md5sum, "a072295d8b564159c1f704b73deafe65")  # the constant hrg_bag knows
        self.assertNotEqual(PrecessionState._md5sum, OldState._md5sum)
        old_bag = self.path("precessed_old.bag")
        with rosbag.Bag(bag_path) as bag, rosbag.Bag(old_bag, "w") as out:
            for topic, m, t in bag.read_messages():
                if topic == "/precession/state":
                    m = OldState(header=m.header, rate=m.rate, angle=m.angle, commands=m.commands)
                out.write(topic, m, t)
        flags = {}
        for name, source in (("new", bag_path), ("old", old_bag)):
            out_bag = self.path("precessed_%s_out.bag" % name)
            code, _, err = hrg_bag("process", source, "--params", self.params, "--out", out_bag)
            self.assertEqual(code, 0, err)
            self.assertRegex(err, r"precession state from /precession/state: 1000 records \(0 dropped\), \d+ outputs "
                                  r"flagged PRECESSING \(0 of them with the state unknown\)")
            with rosbag.Bag(out_bag) as bag:
                outputs = [m for _, m, _ in bag.read_messages(topics=["/output"])]
            flags[name] = [(o.header.stamp.to_nsec(), o.flags) for o in outputs]
        self.assertEqual(flags["new"], flags["old"])
        with rosbag.Bag(bag_path) as bag:
            states = {m.header.stamp.to_nsec(): m for _, m, _ in bag.read_messages(topics=["/precession/state"])}
        stamps = sorted(states)
        expected = []
        for previous, stamp in zip(stamps, stamps[1:]):
            a, b = states[previous], states[stamp]
            expected.append((stamp, 16 if (a.rate != 0.0 or b.rate != 0.0 or a.angle != b.angle) else 0))
        self.assertEqual([(t, f & 16) for t, f in flags["new"]], expected)
        flagged = [t for t, f in expected if f]
        # 2 s at 200 Hz, with the samples at either switch.
        self.assertGreaterEqual(len(flagged), 400)
        self.assertLessEqual(len(flagged), 402)
        self.assertTrue(all(0.99e9 < t - 1e9 < 3.01e9 for t in flagged), flagged[:3] + flagged[-3:])  # start_time 1 s

    def test_simulate_writes_a_triads_topics(self):
        # A triad scenario: exactly each axis's channels and truth under its name, the table, the
        # fixture's log and the body's truth; --no-truth drops the truths; --seed draws the noise and
        # the fixture errors anew; --frame-id names the body frame.
        scenario = self.path("triad.yaml")
        with open(scenario, "w") as f:
            f.write("seed: 3\n"
                    "triad:\n"
                    "  frame_id: fixture\n"
                    "  fixture_error_std: 1.0e-4\n"
                    "  axes:\n"
                    "    - {name: gx, misalignment: [1.0e-4, 0.0], pickoff: {noise: 2.0e-4}}\n"
                    "    - {name: gy, misalignment: [0.0, 0.0], pickoff: {noise: 2.0e-4}}\n"
                    "    - {name: gz, misalignment: [0.0, -1.0e-4], pickoff: {noise: 2.0e-4}}\n"
                    "  positions:\n"
                    "    - {name: z up, up: '+z', profile: [{type: rate, rate: 0.2, duration: 1.0}]}\n"
                    "    - {name: x up, up: '+x', move: 1.0, profile: [{type: dwell, duration: 1.0}]}\n")
        runs = {"truth": [], "no_truth": ["--no-truth"], "seed": ["--seed", "9"], "frame": ["--frame-id", "jig"]}
        topics = {}
        for name, extra in runs.items():
            code, _, err = hrg_bag("simulate", "--scenario", scenario, "--out", self.path("triad_%s.bag" % name),
                                   *extra)
            self.assertEqual(code, 0, err)
            with rosbag.Bag(self.path("triad_%s.bag" % name)) as bag:
                topics[name] = {t: i.msg_type for t, i in bag.get_type_and_topic_info().topics.items()}
        axes = {"/g%s/channels" % a: "hrg_gyro/ChannelAmplitudes" for a in "xyz"}
        common = dict(axes, **{"/turntable/state": "hrg_gyro/TurntableState",
                               "/fixture/position": "hrg_gyro/FixturePosition"})
        self.assertEqual(topics["no_truth"], common)
        with_truth = dict(common, **{"/g%s/truth" % a: "hrg_gyro/GroundTruth" for a in "xyz"})
        with_truth["/truth"] = "hrg_gyro/BodyTruth"
        self.assertEqual(topics["truth"], with_truth)

        def first(bag_name, topic):
            with rosbag.Bag(self.path(bag_name)) as bag:
                return [m for _, m, _ in bag.read_messages(topics=[topic])]
        body, body_seed = first("triad_truth.bag", "/truth"), first("triad_seed.bag", "/truth")
        self.assertEqual({m.header.frame_id for m in body}, {"fixture"})
        self.assertEqual({m.header.frame_id for m in first("triad_frame.bag", "/fixture/position")}, {"jig"})
        self.assertEqual({m.header.frame_id for m in first("triad_truth.bag", "/gy/channels")}, {"gy"})
        # Another seed: other fixture errors (the body's true orientation) and other noise.
        self.assertNotEqual(body[0].body_to_table, body_seed[0].body_to_table)
        self.assertNotEqual(first("triad_truth.bag", "/gx/channels")[0].c_in,
                            first("triad_seed.bag", "/gx/channels")[0].c_in)
        self.assertEqual(hrg_bag("simulate", "--scenario", scenario, "--out", self.path("triad_again.bag"))[0], 0)
        self.assertTrue(filecmp.cmp(self.path("triad_truth.bag"), self.path("triad_again.bag"), shallow=False))

    def test_info_reports_rates_and_validates(self):
        code, out, err = hrg_bag("info", self.short)
        self.assertEqual(code, 0, err)
        self.assertIn("200.00 Hz", out)
        self.assertIn("OK", out)

    def test_bad_bags_get_clear_errors(self):
        self.assertFails(hrg_bag("info", self.path("missing.bag")), 2, "missing")
        truncated = self.path("truncated.bag")
        with open(self.short, "rb") as f:
            data = f.read()
        with open(truncated, "wb") as f:
            f.write(data[: len(data) // 2])
        for sub in (["info", truncated], ["process", truncated, "--params", self.params, "--csv", self.path("t.csv")],
                    ["calibrate", truncated, "--method", "dual_rate", "--out", self.path("t.yaml")],
                    ["allan", truncated]):
            self.assertFails(hrg_bag(*sub), 2, "unindexed")
        wrong = self.path("wrong_types.bag")
        with rosbag.Bag(wrong, "w") as bag:
            for i in range(10):
                bag.write("/channels", String(data="not a gyro"), rospy.Time(1 + i))
        code, out, err = hrg_bag("info", wrong)
        self.assertNotEqual(code, 0)
        self.assertIn("no hrg_gyro/ChannelAmplitudes topic", out + err)
        self.assertFails(hrg_bag("process", wrong, "--params", self.params, "--csv", self.path("w.csv"),
                                 "--channels-topic", "/channels"), 2, "type std_msgs/String")
        no_channels = self.path("no_channels.bag")
        with rosbag.Bag(no_channels, "w") as bag:
            for i in range(10):
                msg = TurntableState()
                msg.header.stamp = rospy.Time(1 + i)
                bag.write("/turntable/state", msg, msg.header.stamp)
        self.assertFails(hrg_bag("process", no_channels, "--params", self.params, "--csv", self.path("n.csv")), 2,
                         "no hrg_gyro/ChannelAmplitudes topic", "/turntable/state")
        self.assertFails(hrg_bag("calibrate", no_channels, "--method", "dual_rate", "--out", self.path("n.yaml")), 2,
                         "no hrg_gyro/ChannelAmplitudes topic")
        self.assertFalse(os.path.exists(self.path("n.yaml")))

    def test_process_csv_has_a_header_and_one_row_per_sample(self):
        out_csv = self.path("short.csv")
        code, out, err = hrg_bag("process", self.short, "--params", self.params, "--csv", out_csv,
                                 "--out", self.path("short_out.bag"))
        self.assertEqual(code, 0, err)
        with open(out_csv) as f:
            rows = list(csv.DictReader(f))
        with rosbag.Bag(self.short) as bag:
            n = bag.get_message_count(topic_filters=["/channels"])
        self.assertEqual(len(rows), n)
        self.assertEqual(rows[0]["status"], "first")
        self.assertTrue(all(r["status"] == "accepted" for r in rows[1:]))
        for r in rows[1:]:
            self.assertTrue(math.isfinite(float(r["dalpha"])) and math.isfinite(float(r["alpha"])))
        with rosbag.Bag(self.path("short_out.bag")) as bag:
            self.assertEqual(bag.get_message_count(topic_filters=["/output"]), n - 1)
            outputs = [m for _, m, _ in bag.read_messages(topics=["/output"])]
        # the CSV and the bag are the same numbers (%.17g round-trips a double)
        for r, o in zip(rows[1:], outputs):
            self.assertEqual(float(r["dalpha"]), o.dalpha)
            self.assertEqual(float(r["alpha"]), o.alpha)

    def test_process_triad_refuses_what_does_not_make_a_triad(self):
        # A triad is three axes' channels; --axis-params names each axis's file (NAME=FILE, as
        # calibrate --method triad); the single axis's options that the triad decides itself are refused.
        triad = os.path.join(self.pkg, "config/triad.yaml")
        out = self.path("triad_refused.csv")
        every = ["--axis-params", "x=" + self.params, "--axis-params", "y=" + self.params,
                 "--axis-params", "z=" + self.params]
        cases = [
            (every[:4], "--axis-params", "z=FILE missing"),
            (every + ["--axis-params", "w=" + self.params], "--axis-params", "'w' is not an axis of the triad"),
            (every[:4] + ["--axis-params", "x=" + self.params], "--axis-params", "gives axis x twice"),
            (every[:4] + ["--axis-params", self.params], "--axis-params", "expects NAME=VALUE"),
            (every + ["--params", self.params], "--params", "--axis-params"),
            (every + ["--frame-id", "imu"], "--frame-id", "excludes"),
            (every + ["--channels-topic", "/channels"], "--channels-topic", "excludes"),
            (every + ["--max-wait", "0"], "--max-wait", "positive"),
            (every + ["--axis-channels", "x=/nowhere"], "/nowhere", "is not in the bag"),
            (every, "/x/channels", "no hrg_gyro/ChannelAmplitudes topic"),  # the single-axis bag
        ]
        for extra, option, why in cases:
            args = ["process", self.short, "--triad", triad, "--csv", out] + extra
            self.assertRefused(hrg_bag(*args), option, why, args)
        for extra, option in ((["--max-wait", "1"], "--max-wait"), (["--axis-params", "x=" + self.params],
                                                                     "--axis-params")):
            args = ["process", self.short, "--params", self.params] + extra
            self.assertRefused(hrg_bag(*args), option, "requires --triad", args)
        self.assertFalse(os.path.exists(out), "a refused process writes nothing")

    def test_triad_axes_reading_one_channels_topic_are_refused(self):
        # --axis-channels y=/x/channels: y would read x's channels, which x reads by default. Both
        # process --triad and calibrate --method triad refuse it (exit 2) naming both axes and the topic.
        bag_path = self.path("three_axes.bag")
        with rosbag.Bag(bag_path, "w") as bag:
            for a in ("x", "y", "z", "w"):
                m = ChannelAmplitudes()
                m.header.stamp = rospy.Time(1)
                bag.write("/%s/channels" % a, m, rospy.Time(1))
        triad = os.path.join(self.pkg, "config/triad.yaml")
        every = ["--axis-params", "x=" + self.params, "--axis-params", "y=" + self.params,
                 "--axis-params", "z=" + self.params]
        out, csv_out = self.path("one_topic.yaml"), self.path("one_topic.csv")
        commands = (["process", bag_path, "--triad", triad, "--csv", csv_out],
                    ["calibrate", bag_path, "--method", "triad", "--triad", triad, "--out", out])
        cases = [
            (["--axis-channels", "y=/x/channels"], "axes x and y both read the channels topic /x/channels"),
            (["--axis-channels", "x=/z/channels"], "axes x and z both read the channels topic /z/channels"),
            (["--axis-channels", "y=/w/channels", "--axis-channels", "z=/w/channels"],
             "axes y and z both read the channels topic /w/channels"),
        ]
        for command in commands:
            for extra, why in cases:
                args = command + every + extra
                self.assertRefused(hrg_bag(*args), "--axis-channels", why, args)
        self.assertFalse(os.path.exists(out) or os.path.exists(csv_out), "a refused run writes nothing")

    def test_calibrate_refuses_what_the_gates_refuse(self):
        out, report = self.path("refused.yaml"), self.path("refused.report.yaml")
        code, stdout, err = hrg_bag("calibrate", self.short, "--method", "dual_rate", "--params", self.params,
                                    "--out", out, "--report", report)
        self.assertEqual(code, 1, stdout + err)
        self.assertFalse(os.path.exists(out), "a refused calibration writes no parameter file")
        with open(report) as f:
            r = yaml.safe_load(f)
        self.assertFalse(r["accepted"])
        self.assertTrue(r["reason"])

    def test_calibrate_step_method(self):
        bag, out = self.path("steps.bag"), self.path("steps.yaml")
        self.assertEqual(hrg_bag("simulate", "--scenario", os.path.join(self.pkg, "config/scenarios/steps.yaml"),
                                 "--out", bag)[0], 0)
        code, stdout, err = hrg_bag("calibrate", bag, "--method", "step", "--params", self.params, "--out", out)
        self.assertEqual(code, 0, stdout + err)
        with open(out) as f:
            p = yaml.safe_load(f)
        self.assertEqual(p["calibration"]["method"], "step")
        self.assertAlmostEqual(p["scale_factor"]["mean"], -0.56, delta=0.56 * 1e-3)

    def test_calibrate_refreshes_its_prior_in_place_keeping_a_backup(self):
        # --params X --out X, as the live calibrator refreshes its file: accepted -> X replaced and
        # the prior kept as X.bak; through a link to X too; refused -> X untouched, no backup.
        d = self.path("in_place")
        os.makedirs(d)
        bag, prior = os.path.join(d, "steps.bag"), os.path.join(d, "prior.yaml")
        self.assertEqual(hrg_bag("simulate", "--scenario", os.path.join(self.pkg, "config/scenarios/steps.yaml"),
                                 "--out", bag)[0], 0)
        shutil.copy(self.params, prior)
        with open(prior, "rb") as f:
            prior_bytes = f.read()
        os.symlink("prior.yaml", os.path.join(d, "link.yaml"))
        code, stdout, err = hrg_bag("calibrate", bag, "--method", "step", "--params", prior, "--out",
                                    os.path.join(d, "link.yaml"))
        self.assertEqual(code, 0, stdout + err)
        self.assertTrue(os.path.islink(os.path.join(d, "link.yaml")))
        with open(prior) as f:
            self.assertEqual(yaml.safe_load(f)["calibration"]["method"], "step")
        with open(prior + ".bak", "rb") as f:
            self.assertEqual(f.read(), prior_bytes)
        # A method the session cannot serve (no plateaus of two rates): refused, nothing replaced.
        shutil.copy(self.params, prior)
        os.remove(prior + ".bak")
        code, stdout, err = hrg_bag("calibrate", bag, "--method", "dual_rate", "--params", prior, "--out", prior)
        self.assertEqual(code, 1, stdout + err)
        with open(prior, "rb") as f:
            self.assertEqual(f.read(), prior_bytes)
        self.assertEqual(sorted(os.listdir(d)), ["link.yaml", "prior.yaml", "steps.bag"])

    def test_allan_reads_the_angle_random_walk(self):
        bag, out_csv, out_yaml = self.path("static.bag"), self.path("allan.csv"), self.path("allan.yaml")
        self.assertEqual(hrg_bag("simulate", "--scenario", os.path.join(self.pkg, "test/scenarios/static_noise.yaml"),
                                 "--out", bag)[0], 0)
        code, stdout, err = hrg_bag("allan", bag, "--params", self.params, "--csv", out_csv, "--yaml", out_yaml)
        self.assertEqual(code, 0, err)
        self.assertIn("angle random walk", stdout)
        line = [l for l in stdout.splitlines() if "angle random walk" in l][0]
        self.assertNotIn("not identified", line)
        with open(out_csv) as f:
            rows = list(csv.DictReader(f))
        self.assertGreater(len(rows), 10)
        # sigma(1 s) of a 1e-4 rad/sqrt(s) random walk is 1e-4 rad/s
        near = min(rows, key=lambda r: abs(math.log(float(r["tau"]))))
        self.assertAlmostEqual(float(near["tau"]), 1.0, delta=0.2)
        self.assertAlmostEqual(float(near["deviation"]), 1e-4, delta=0.15e-4)
        # The readings file (the alignment's noise/allan_file reads it): N identified, in SI.
        with open(out_yaml) as f:
            readings = yaml.safe_load(f)
        self.assertTrue(readings["angle_random_walk"]["identified"])
        self.assertAlmostEqual(readings["angle_random_walk"]["value"], 1e-4, delta=0.15e-4)
        self.assertEqual(readings["samples"] * readings["tau0"], readings["record_length"])

    def test_the_documented_chain_on_the_dual_rate_scenario(self):
        bag, out, report = self.path("dual_rate.bag"), self.path("calibrated.yaml"), self.path("report.yaml")
        code, _, err = hrg_bag("simulate", "--scenario", os.path.join(self.pkg, "config/scenarios/dual_rate.yaml"),
                               "--out", bag)
        self.assertEqual(code, 0, err)
        code, out_info, err = hrg_bag("info", bag)
        self.assertEqual(code, 0, out_info + err)
        code, stdout, err = hrg_bag("calibrate", bag, "--method", "dual_rate", "--params", self.params, "--out", out,
                                    "--report", report)
        self.assertEqual(code, 0, stdout + err)
        with open(out) as f:
            p = yaml.safe_load(f)
        self.assertEqual(p["calibration"]["method"], "dual_rate")
        with open(report) as f:
            r = yaml.safe_load(f)
        self.assertTrue(r["accepted"])
        out_csv = self.path("dual_rate.csv")
        code, _, err = hrg_bag("process", bag, "--params", out, "--csv", out_csv)
        self.assertEqual(code, 0, err)
        with open(out_csv) as f:
            rows = sum(1 for _ in f) - 1
        with rosbag.Bag(bag) as b:
            self.assertEqual(rows, b.get_message_count(topic_filters=["/channels"]))

    def test_every_subcommand_refuses_bad_arguments_naming_the_option(self):
        bag, params = self.short, self.params
        scenario = os.path.join(self.pkg, "test/scenarios/short_session.yaml")
        common = {
            "simulate": ["simulate", "--scenario", scenario, "--out", self.path("bad_args.bag")],
            "info": ["info", bag],
            "process": ["process", bag, "--params", params, "--csv", self.path("bad_args.csv")],
            "calibrate": ["calibrate", bag, "--method", "dual_rate", "--params", params,
                          "--out", self.path("bad_args.yaml")],
            "allan": ["allan", bag, "--params", params],
        }
        limits = [  # the processor node refuses each of these (core::validate), so must every subcommand
            (["--max-gap", "-1"], "--max-gap", "positive"),
            (["--max-gap", "0"], "--max-gap", "positive"),
            (["--max-gap", "12x"], "--max-gap", "finite number"),
            (["--max-gap", "nan"], "--max-gap", "finite number"),
            (["--max-gap", "inf"], "--max-gap", "finite number"),
            (["--backward-reset", "-5"], "--backward-reset", "positive"),
            (["--max-rate", "0"], "--max-rate", "positive"),
            (["--max-rate", "abc"], "--max-rate", "finite number"),
            (["--min-anisotropy", "2"], "--min-anisotropy", "between 0 and 1"),
            (["--min-anisotropy", "0"], "--min-anisotropy", "between 0 and 1"),
            (["--min-amplitude", "-1"], "--min-amplitude", ">= 0"),
            (["--max-amplitude", "0"], "--max-amplitude", "above --min-amplitude"),
            (["--min-amplitude", "5", "--max-amplitude", "1"], "--max-amplitude", "above --min-amplitude"),
            (["--max-gap"], "--max-gap", "missing"),
        ]
        cases = []
        for sub in ("process", "calibrate", "allan"):
            cases += [(common[sub] + extra, option, why) for extra, option, why in limits]
        for sub in ("process", "simulate"):
            cases.append((common[sub] + ["--compression", "zip"], "--compression", "zip"))
        cases += [
            (common["simulate"] + ["--seed", "1e99"], "--seed", "whole number"),
            (common["simulate"] + ["--seed", "-1"], "--seed", "whole number"),
            (common["simulate"] + ["--seed", "12x"], "--seed", "whole number"),
            (common["simulate"] + ["--seed", "0x10"], "--seed", "whole number"),
            (common["simulate"] + ["--seed", "18446744073709551616"], "--seed", "whole number"),
            (common["simulate"] + ["--frame-id", ""], "--frame-id", "empty"),
            (["simulate", "--out", self.path("bad_args.bag")], "--scenario", "required"),
            (common["info"] + ["--gap", "abc"], "--gap", "finite number"),
            (common["info"] + ["--gap", "3x"], "--gap", "finite number"),
            (common["info"] + ["--gap", "0.5"], "--gap", "above 1"),
            (common["info"] + ["--channels-topic", ""], "--channels-topic", "empty"),
            (["info"], "BAG", "required"),
            (common["process"] + ["--frame-id", ""], "--frame-id", "empty"),
            (common["process"] + ["--frame-id", "gyro\nlink"], "--frame-id", "control characters"),
            (common["simulate"] + ["--frame-id", "/gyro_link"], "--frame-id", "tf2"),
            (["process", bag], "--params", "required"),
            (common["calibrate"] + ["--method", "bogus"], "--method", "unknown method"),
            (common["calibrate"] + ["--plot", self.path("x.png")], "--plot", "--report"),
            (["calibrate", bag, "--method", "step"], "--out", "required"),
            (common["allan"] + ["--plot", self.path("x.png")], "--plot", "--csv"),
            (common["allan"] + ["--csv"], "--csv", "missing"),
            (common["allan"] + ["--from", "abc"], "--from", "finite number"),
            (common["allan"] + ["--from", "5", "--to", "1"], "--from", "before --to"),
        ]
        for args, option, why in cases:
            self.assertRefused(hrg_bag(*args), option, why, args)
        self.assertFalse(os.path.exists(self.path("bad_args.bag")), "a refused simulate writes nothing")
        self.assertFalse(os.path.exists(self.path("bad_args.csv")), "a refused process writes nothing")
        self.assertFalse(os.path.exists(self.path("bad_args.yaml")), "a refused calibrate writes nothing")

    def test_every_tool_lists_the_core_methods_in_its_help(self):
        # The refusal of an unknown method prints the core's one list; each --help names all of it
        # that the tool runs (hrg_session simulates one axis: every method but the triad's, which it
        # refuses pointing to hrg_bag calibrate).
        common = ["--calibration", self.params, "--verification", self.params, "--params", self.params]
        for tool, refused, helped, single_axis in (
                ("hrg_bag calibrate", hrg_bag("calibrate", self.short, "--out", self.path("m.yaml"), "--method", "x"),
                 hrg_bag("calibrate", "--help"), False),
                ("hrg_session", run(HRG_SESSION, *(common + ["--method", "x"])), run(HRG_SESSION, "--help"), True)):
            match = re.search(r"unknown method 'x' \(([a-z_, ]+)\)", refused[2])
            self.assertTrue(match, "%s: %s" % (tool, refused[2]))
            methods = match.group(1).split(", ")
            self.assertEqual(len(methods), 7, methods)  # with the triad and the field calibrations
            listed = [m for m in methods if not (single_axis and m == "triad")]
            self.assertIn("|".join(listed) + ("\n" if single_axis else ""), helped[1], tool)
        triad = run(HRG_SESSION, *(common + ["--method", "triad"]))
        self.assertEqual(triad[0], 2, triad[2])
        self.assertIn("hrg_bag calibrate --method triad", triad[2])

    def test_calibrate_config_errors_name_the_file_and_key(self):
        config = self.path("bad_settings.yaml")
        with open(config, "w") as f:
            f.write("bins: 0\n")
        self.assertRefused(hrg_bag("calibrate", self.short, "--out", self.path("c.yaml"), "--config", config),
                           "--config", "bins", ["--config", config])

    def test_process_exits_1_with_the_counts_when_no_sample_is_accepted(self):
        # A plausible-amplitude window that the simulated wave (amplitude about 1) never enters.
        code, _, err = hrg_bag("process", self.short, "--params", self.params, "--csv", self.path("none.csv"),
                               "--min-amplitude", "1e5", "--max-amplitude", "1e6")
        self.assertEqual(code, 1, err)
        self.assertIn("no sample accepted", err)
        with rosbag.Bag(self.short) as bag:
            n = bag.get_message_count(topic_filters=["/channels"])
        self.assertIn("%d amplitude out of range" % n, err)
        # the same limits inside the node's rules and the wave's range: accepted, exit 0
        code, _, err = hrg_bag("process", self.short, "--params", self.params, "--min-amplitude", "0.001",
                               "--max-amplitude", "1e3", "--max-gap", "0.5", "--max-rate", "10")
        self.assertEqual(code, 0, err)

    def test_hrg_session_refuses_bad_arguments_naming_the_option(self):
        base = ["--calibration", os.path.join(self.pkg, "test/scenarios/short_session.yaml"),
                "--verification", os.path.join(self.pkg, "test/scenarios/short_session.yaml"),
                "--params", self.params, "--out", self.path("session.yaml")]
        cases = [
            (["--window", "abc"], "--window", "finite number"),
            (["--window", "2x"], "--window", "finite number"),
            (["--window", "0"], "--window", "positive"),
            (["--window", "-1"], "--window", "positive"),
            (["--bins", "12x"], "--bins", "whole number"),
            (["--bins", "0"], "--bins", "[8, 4096]"),
            (["--bins", "99999999999"], "--bins", "[8, 4096]"),
            (["--orders", "3"], "--orders", "even"),
            (["--orders", "4,2"], "--orders", "increasing"),
            (["--orders", "2,x"], "--orders", "whole number"),
            (["--drift-orders", "2x"], "--drift-orders", "whole number"),
            (["--drift-orders", "0"], "--drift-orders", "[2, 64]"),
            (["--evaluation-orders", "2,3"], "--evaluation-orders", "even"),
            (["--evaluation-orders", "0"], "--evaluation-orders", "[2, 64]"),
            (["--method", "bogus"], "--method", "unknown method"),
            (["--bins"], "--bins", "missing"),
            (["--frobnicate", "1"], "--frobnicate", "not expected"),
        ]
        for extra, option, why in cases:
            self.assertRefused(run(HRG_SESSION, *(base + extra)), option, why, extra)
        self.assertRefused(run(HRG_SESSION, *base[2:]), "--calibration", "required", base[2:])
        self.assertFalse(os.path.exists(self.path("session.yaml")))
        code, out, _ = run(HRG_SESSION, "--help")
        self.assertEqual(code, 0)
        for option in ("--window", "--bins", "--orders", "--method", "--evaluation-orders"):
            self.assertIn(option, out)

    def test_an_output_that_is_an_input_or_a_directory_is_refused_before_any_work(self):
        # The red-team cases: each would have destroyed the recording (or the scenario) being read.
        d = self.path("same_file")
        os.makedirs(os.path.join(d, "outdir"))
        rec, params, scenario = (os.path.join(d, n) for n in ("rec.bag", "p.yaml", "s.yaml"))
        shutil.copy(self.short, rec)
        shutil.copy(self.params, params)
        shutil.copy(os.path.join(self.pkg, "test/scenarios/short_session.yaml"), scenario)
        os.symlink("rec.bag", os.path.join(d, "link_to_rec.bag"))
        os.link(rec, os.path.join(d, "hard_link.bag"))
        before = snapshot(d)
        cal = ["calibrate", rec, "--method", "dual_rate", "--params", params]
        cases = [
            (["process", rec, "--params", params, "--out", rec], "same file"),
            (["process", rec, "--params", params, "--csv", rec], "same file"),
            (["process", rec, "--params", params, "--out", os.path.join(d, "link_to_rec.bag")], "same file"),
            (["process", rec, "--params", params, "--out", os.path.join(d, "hard_link.bag")], "same file"),
            (["process", rec, "--params", params, "--csv", os.path.join(d, "./../same_file/rec.bag")], "same file"),
            (["process", rec, "--params", params, "--out", params], "same file"),
            (["process", rec, "--params", params, "--out", os.path.join(d, "o.bag"), "--csv",
              os.path.join(d, "o.bag")], "are the same file"),
            (["allan", rec, "--csv", rec], "same file"),
            (["allan", rec, "--csv", os.path.join(d, "a.csv"), "--plot", os.path.join(d, "a.csv")], "same file"),
            (cal + ["--out", rec], "same file"),
            (cal + ["--out", os.path.join(d, "c.yaml"), "--report", rec], "same file"),
            (cal + ["--out", os.path.join(d, "c.yaml"), "--report", params], "same file"),
            (["simulate", "--scenario", scenario, "--out", scenario], "same file"),
            (["process", rec, "--params", params, "--out", os.path.join(d, "outdir")], "is a directory"),
            (["process", rec, "--params", params, "--csv", os.path.join(d, "outdir")], "is a directory"),
            (cal + ["--out", os.path.join(d, "outdir")], "is a directory"),
            (["simulate", "--scenario", scenario, "--out", os.path.join(d, "outdir")], "is a directory"),
        ]
        for args, why in cases:
            code, _, err = hrg_bag(*args)
            self.assertEqual(code, 2, "%s -> exit %d\n%s" % (args, code, err))
            self.assertIn(why, err, args)
            self.assertNotIn("terminate called", err, args)
            if why == "same file":
                self.assertIn(args[-1], err, "the message names the output: %s" % args)
            self.assertEqual(snapshot(d), before, "nothing changed, no .bak, no temporary: %s" % (args,))
        session = ["--calibration", scenario, "--verification", scenario, "--params", params]
        for out, why in ((params, "same file"), (scenario, "same file"), (os.path.join(d, "outdir"), "not a regular")):
            code, _, err = run(HRG_SESSION, *(session + ["--out", out]))
            self.assertEqual(code, 2, err)
            self.assertIn("--out", err)
            self.assertIn(why, err)
            self.assertEqual(snapshot(d), before)

    def test_triad_outputs_that_are_other_inputs_are_refused_before_any_work(self):
        # Each output of calibrate --method triad against every input and every other output, by file
        # identity: only an output naming its own prior (refreshed in place) may be an input.
        d = self.path("triad_same_file")
        os.makedirs(os.path.join(d, "sub"))
        os.makedirs(os.path.join(d, "out"))
        bag = os.path.join(d, "session.bag")
        os.link(self.triad_bag(), bag)
        triad, axes = self.triad_priors(d)
        shutil.copy(triad, triad + ".bak")
        os.symlink("x.yaml", os.path.join(d, "link_to_x.yaml"))
        os.link(axes["y"], os.path.join(d, "hard_y.yaml"))
        bag_state = os.stat(bag)
        elsewhere = ["--out", os.path.join(d, "out/triad.yaml")]  # the axis files beside it by default
        outs = elsewhere + ["--axis-out=%s=%s" % (a, os.path.join(d, "out", a + ".yaml")) for a in "xyz"]
        before = {n: v for n, v in snapshot(d).items() if n != "session.bag"}
        cases = [
            # --out an axis's prior: through its default axis files beside it, and on its own
            (["--out", axes["x"]], axes["x"], axes["x"]),
            (["--out", axes["x"]] + outs[2:], axes["x"], axes["x"]),
            (["--out", os.path.join(d, "link_to_x.yaml")] + outs[2:], "link_to_x.yaml", axes["x"]),
            # --axis-out the triad prior, another axis's prior (also through a hard link, dir/../), the bag
            (elsewhere + ["--axis-out", "x=" + triad], triad, triad),
            (elsewhere + ["--axis-out", "x=" + axes["y"]], axes["y"], axes["y"]),
            (elsewhere + ["--axis-out", "z=" + os.path.join(d, "hard_y.yaml")], "hard_y.yaml", axes["y"]),
            (elsewhere + ["--axis-out", "y=" + os.path.join(d, "sub/../z.yaml")], "sub/../z.yaml", axes["z"]),
            (elsewhere + ["--axis-out", "x=" + bag], bag, bag),
            # two outputs on one file; a report over a prior
            (elsewhere + ["--axis-out", "y=" + os.path.join(d, "out/x.yaml")], "out/x.yaml", "out/x.yaml"),
            (outs + ["--report", axes["z"]], axes["z"], axes["z"]),
        ]
        for extra, output, other in cases:
            args = self.triad_calibrate(bag, triad, axes, *extra)
            code, _, err = hrg_bag(*args, timeout=60)
            self.assertEqual(code, 2, "%s -> exit %d\n%s" % (extra, code, err))
            self.assertIn("same file", err, extra)
            self.assertIn(output, err, extra)
            self.assertIn(other, err, extra)
            self.assertNotIn("terminate called", err, extra)
            self.assertEqual({n: v for n, v in snapshot(d).items() if n != "session.bag"}, before,
                             "nothing changed, no .bak, no temporary: %s" % (extra,))
        # The triad file refreshed from its own backup: writing it would replace that input.
        args = self.triad_calibrate(bag, triad + ".bak", axes, "--out", triad)
        code, _, err = hrg_bag(*args, timeout=60)
        self.assertEqual(code, 2, err)
        self.assertIn("keeps its previous version as '%s.bak'" % triad, err)
        self.assertEqual({n: v for n, v in snapshot(d).items() if n != "session.bag"}, before)
        after = os.stat(bag)
        self.assertEqual((after.st_ino, after.st_size, after.st_mtime_ns),
                         (bag_state.st_ino, bag_state.st_size, bag_state.st_mtime_ns))

    def test_triad_calibration_refreshes_its_four_files_in_place_and_a_full_disk_replaces_none(self):
        # The four outputs are one set: on a full disk (none fits, or the first two would) none is
        # replaced, every old file and its .bak stay as they were, and no temporary is left.
        bag = self.triad_bag()
        with small_disk(self.path("triad_disk"), "256k") as (disk, why):
            d = disk or self.path("triad_in_place")
            os.makedirs(d, exist_ok=True)
            triad, axes = self.triad_priors(d)
            priors = snapshot(d)
            args = self.triad_calibrate(bag, triad, axes, "--out", triad, "--report",
                                        self.path("triad_in_place.report.yaml"))
            code, out, err = hrg_bag(*args)
            self.assertEqual(code, 0, out + err)
            refreshed = snapshot(d)
            self.assertEqual(sorted(refreshed), sorted(list(priors) + [n + ".bak" for n in priors]))
            for name, content in priors.items():
                self.assertEqual(refreshed[name + ".bak"], content, "the prior kept as %s.bak" % name)
                self.assertNotEqual(refreshed[name], content, name)
            for a in "xyz":
                with open(axes[a]) as f:
                    self.assertEqual(yaml.safe_load(f)["calibration"]["method"], "triad")
            if disk is None:
                self.skipTest(why)
            sizes = sorted(os.path.getsize(axes[a]) for a in "xyz")
            # Nothing free; then room for two axis files at most (tmpfs gives each file whole pages).
            page = os.statvfs(disk).f_frsize
            two = 2 * page * -(-sizes[-1] // page)
            for leave in (0, two):
                filler = fill(disk, leave)
                before = snapshot(disk)
                code, out, err = hrg_bag(*args)
                self.assertEqual(code, 3, "%d bytes free -> exit %d\n%s" % (leave, code, out + err))
                self.assertIn("No space left on device", err)
                self.assertIn("nothing of the set was replaced", err)
                self.assertNotIn("wrote", out)
                self.assertNotIn("terminate called", err)
                self.assertEqual(snapshot(disk), before, "%d bytes free: the old set and its backups as they were,"
                                 " no temporary" % leave)
                os.remove(filler)

    def test_fifos_devices_and_directories_are_refused_as_inputs_without_blocking(self):
        # A FIFO without a writer blocks an ordinary open forever: every input is checked before it is
        # opened, so each case ends at once (the short timeout turns a regression into a failure).
        d = self.path("not_files")
        os.makedirs(os.path.join(d, "a_directory"))
        fifo = os.path.join(d, "fifo")
        os.mkfifo(fifo)
        scenario = os.path.join(self.pkg, "test/scenarios/short_session.yaml")
        kinds = ((fifo, "is a FIFO"), ("/dev/null", "is a character device"),
                 (os.path.join(d, "a_directory"), "is a directory"))
        for bad, why in kinds:
            cases = [
                ["info", bad],
                ["process", bad, "--params", self.params, "--csv", os.path.join(d, "p.csv")],
                ["calibrate", bad, "--method", "dual_rate", "--out", os.path.join(d, "c.yaml")],
                ["allan", bad],
                ["export", bad, "--channels-csv", os.path.join(d, "e.csv")],
                ["process", self.short, "--params", bad, "--csv", os.path.join(d, "p.csv")],
                ["calibrate", self.short, "--method", "dual_rate", "--out", os.path.join(d, "c.yaml"), "--config",
                 bad],
                ["calibrate", self.short, "--method", "dual_rate", "--out", os.path.join(d, "c.yaml"), "--params",
                 bad],
                ["allan", self.short, "--params", bad],
                ["simulate", "--scenario", bad, "--out", os.path.join(d, "s.bag")],
            ]
            for args in cases:
                code, _, err = hrg_bag(*args, timeout=20)
                self.assertEqual(code, 2, "%s -> exit %d\n%s" % (args, code, err))
                self.assertIn(bad, err, args)
                self.assertIn(why, err, args)
                self.assertNotIn("terminate called", err, args)
            for option in ("--calibration", "--verification", "--params"):
                args = ["--calibration", scenario, "--verification", scenario, "--params", self.params]
                args[args.index(option) + 1] = bad
                code, _, err = run(HRG_SESSION, *args, timeout=20)
                self.assertEqual(code, 2, "%s -> exit %d\n%s" % (args, code, err))
                self.assertIn(why, err, args)
        self.assertEqual(sorted(os.listdir(d)), ["a_directory", "fifo"], "nothing written")

    def test_outputs_replace_their_files_only_when_complete(self):
        d = self.path("replace")
        os.makedirs(d)
        out_bag, out_csv = os.path.join(d, "out.bag"), os.path.join(d, "out.csv")
        for p in (out_bag, out_csv):
            with open(p, "w") as f:
                f.write("previous\n")
            os.chmod(p, 0o640)
        code, _, err = hrg_bag("process", self.short, "--params", self.params, "--out", out_bag, "--csv", out_csv)
        self.assertEqual(code, 0, err)
        self.assertEqual(sorted(os.listdir(d)), ["out.bag", "out.csv"], "no temporary left")
        with rosbag.Bag(out_bag) as bag:
            self.assertGreater(bag.get_message_count(topic_filters=["/output"]), 6000)
        self.assertEqual(os.stat(out_bag).st_mode & 0o777, 0o640, "a replaced file keeps its mode")
        # A plot replaces its file only when the plotter succeeded: here its matplotlib is broken.
        plot = os.path.join(d, "allan.png")
        with open(plot, "w") as f:
            f.write("previous plot\n")
        broken = os.path.join(d, "broken_python")
        os.makedirs(os.path.join(broken, "matplotlib"))
        with open(os.path.join(broken, "matplotlib", "__init__.py"), "w") as f:
            f.write("raise ImportError('matplotlib made unusable by the test')\n")
        env = dict(os.environ, PYTHONPATH=broken)
        code, _, err = hrg_bag("allan", self.short, "--params", self.params, "--csv", os.path.join(d, "a.csv"),
                               "--plot", plot, env=env)
        self.assertEqual(code, 3, err)
        self.assertIn("not written", err)
        with open(plot) as f:
            self.assertEqual(f.read(), "previous plot\n")
        self.assertEqual(sorted(n for n in os.listdir(d) if "allan.png" in n), ["allan.png"], "no temporary left")
        code, _, err = hrg_bag("allan", self.short, "--params", self.params, "--csv", os.path.join(d, "a.csv"),
                               "--plot", plot)
        self.assertEqual(code, 0, err)
        with open(plot, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", "a PNG replaced the old file")
        self.assertEqual(sorted(n for n in os.listdir(d) if "allan.png" in n), ["allan.png"])

    def test_a_full_disk_fails_with_exit_3_and_leaves_the_target_as_it_was(self):
        with small_disk(self.path("full_disk"), "64k") as (disk, why):
            if disk is None:
                self.skipTest(why)
            existing = {n: os.path.join(disk, n) for n in ("old.bag", "old.csv", "old.report.yaml", "old_allan.csv")}
            for p in existing.values():
                with open(p, "w") as f:
                    f.write("previous content\n")
            new = {n: os.path.join(disk, n) for n in ("new.bag", "new.csv", "new.report.yaml", "new_allan.csv")}
            process = ["process", self.short, "--params", self.params]
            calibrate = ["calibrate", self.short, "--method", "dual_rate", "--params", self.params,
                         "--out", self.path("never_accepted.yaml")]
            allan = ["allan", self.short, "--params", self.params]
            cases = []
            for kind in ("new", "old"):
                paths = new if kind == "new" else existing
                cases += [
                    process + ["--out", paths[kind + ".bag"]],
                    process + ["--csv", paths[kind + ".csv"]],
                    calibrate + ["--report", paths[kind + ".report.yaml"]],
                    allan + ["--csv", paths[kind + "_allan.csv"]],
                ]
            # Nothing free at all, then 24 KiB free: the large outputs then fail in the middle of the
            # bag or the CSV (a small report or Allan CSV may then fit, and is not tried).
            for leave in (0, 24 * 1024):
                filler = fill(disk, leave)
                before = snapshot(disk)
                for args in (cases if leave == 0 else [c for c in cases if c[0] == "process"]):
                    code, _, err = hrg_bag(*args)
                    self.assertEqual(code, 3, "%s, %d bytes free -> exit %d\n%s" % (args, leave, code, err))
                    self.assertIn(args[-1], err)
                    self.assertIn("No space left on device", err, args)
                    self.assertNotIn("terminate called", err)
                    self.assertEqual(snapshot(disk), before, "target untouched, no temporary: %s" % (args,))
                os.remove(filler)


if __name__ == "__main__":
    rospy.init_node("hrg_bag_cli_test")
    rostest.rosrun("hrg_gyro", "hrg_bag_cli", HrgBagCli)
