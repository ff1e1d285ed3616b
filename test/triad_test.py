#!/usr/bin/env python3
"""Three simulated gyros, their processors and the triad in one nodelet manager (test/triad.test).

The triad's Imu is checked field by field against the axes' own outputs of the same stamp: frame,
stamps, omega_body = M r - bias (1e-12), covariance M diag(sigma_i^2) M^T from the axes' Imu
variances, symmetric and positive definite, REP-145's -1 markers, and no Imu for a flagged sample.
Axis y loses 3 channel samples (its processor integrates across them): those stamps are not
published and the next is combined over all four intervals, nothing lost; then y loses 0.3 s (a gap
on y): each stamp it lacks is a FLAG_GAP sample, never a mix. Glitched stamps: one channel sample of
x stamped 1000 s ahead, one of z 100 s back, and a stray output on /x/output two periods back: each
costs that sample only, no reset, no epoch. ~reload takes a good file and refuses a bad one naming
the key; diagnostics, the static transform, and `hrg_bag process --triad` on the recorded channels
(bit for bit the live TriadOutput) complete it."""
import math
import os
import re
import shutil
import subprocess
import sys
import time
import unittest

import numpy as np
import rosbag
import rosgraph
import rospy
import rostest
import tf2_ros
import yaml
from diagnostic_msgs.msg import DiagnosticArray
from nodelet.srv import NodeletList
from sensor_msgs.msg import Imu
from std_msgs.msg import Bool
from std_srvs.srv import Trigger

from hrg_gyro.msg import ChannelAmplitudes, GyroOutput, TriadOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

AXES = ("x", "y", "z")
TABLE_RATES = {"x": 0.1, "y": -0.05, "z": 0.2}  # rad/s, test/scenarios/triad_*.yaml
EARTH_VERTICAL = 7.2921150e-5 * math.sin(0.9)  # rad/s at the scenarios' latitude
FLAG_GAP, FLAG_RESET = TriadOutput.FLAG_GAP, TriadOutput.FLAG_RESET
HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
TRIAD_FIELDS = ("dt", "flags")
MARGIN = 500000000  # ns after a refused reload
SWAP = re.compile(r"in force after stamp (\d+)\.(\d{9})")


def ns(msg):
    return msg.header.stamp.to_nsec()


def triad_matrix(path):
    t = util.load_yaml(path)
    return np.array(t["axis_to_body"], dtype=float), np.array(t["bias"], dtype=float), t


def vector(v):
    return np.array([v.x, v.y, v.z])


def same(a, b):
    return a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))


class Triad(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = rospy.get_param("~work_dir")
        cls.triad_file = rospy.get_param("~triad_file")
        cls.original = rospy.get_param("~original_triad_file")
        cls.params = rospy.get_param("~parameter_file")
        cls.m, cls.bias, cls.triad = triad_matrix(cls.original)
        # The triad must hear every output from the first: wait for its six subscriptions.
        master = rosgraph.Master("/triad_test")
        wanted = ["/%s/%s" % (a, t) for a in AXES for t in ("output", "imu/data_raw")]

        def subscribed():
            subs = dict(master.getSystemState()[1])
            return all(subs.get(t) for t in wanted)
        util.wait_for(subscribed, "the triad's subscriptions to the axes")
        cls.outputs = {a: util.Latest("/%s/output" % a, GyroOutput, keep_all=True) for a in AXES}
        cls.axis_imu = {a: util.Latest("/%s/imu/data_raw" % a, Imu, keep_all=True) for a in AXES}
        cls.imu = util.Latest("/imu/data_raw", Imu, keep_all=True)
        cls.triad_out = util.Latest("/triad/output", TriadOutput, keep_all=True)
        listeners = list(cls.outputs.values()) + list(cls.axis_imu.values()) + [cls.imu, cls.triad_out]
        util.wait_for(lambda: all(s.sub.get_num_connections() > 0 for s in listeners),
                      "this test's connections to the outputs")
        time.sleep(1.0)
        # The drivers start when this test (and each processor) listens to their channels.
        cls.channels = {a: util.Latest("/%s/channels" % a, ChannelAmplitudes, keep_all=True) for a in AXES}
        cls.statuses = {}
        cls.status_rounds = {}
        cls.diag_sub = rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        done = {a: util.Latest("/%s/driver_sim/done" % a, Bool) for a in AXES}
        util.wait_for_service("/triad/reload")
        reload = rospy.ServiceProxy("/triad/reload", Trigger)
        stray_pub = rospy.Publisher("/x/output", GyroOutput, queue_size=1)
        util.wait_for(lambda: cls.triad_out.count > 100, "triad outputs")

        # A stray output on /x/output stamped two periods (and 1 ms) behind x's newest, at 5 s of sim time.
        util.wait_for(lambda: rospy.get_rostime().to_sec() > 5.0, "sim time 5 s")
        util.wait_for(lambda: stray_pub.get_num_connections() >= 2, "the triad's subscription to the stray output")
        stray = GyroOutput()
        stray.header.stamp = rospy.Time(nsecs=ns(cls.outputs["x"].msg) - 2 * 5000000 - 1000000)
        stray.header.frame_id = "x_gyro_link"
        stray.dt, stray.dalpha, stray.rate = 0.005, 0.5, 100.0
        cls.stray_stamp = ns(stray)
        stray_pub.publish(stray)

        # A good file (another bias) at 10 s of sim time, a bad one (M far from the identity) at 14 s.
        util.wait_for(lambda: rospy.get_rostime().to_sec() > 10.0, "sim time 10 s")
        cls.new_bias = np.array([-3.0e-4, 4.0e-4, 1.0e-4])
        good = dict(cls.triad, bias=cls.new_bias.tolist())
        with open(cls.triad_file, "w") as f:
            yaml.safe_dump(good, f)
        cls.good = reload()
        # The triad says after which stamp the new file applies (it may run behind /clock on a busy host).
        swap = SWAP.search(cls.good.message)
        if not swap:
            raise AssertionError("the reload's answer names no stamp: %s" % cls.good.message)
        cls.good_swap = int(swap.group(1)) * 1000000000 + int(swap.group(2))
        util.wait_for(lambda: rospy.get_rostime().to_sec() > 14.0, "sim time 14 s")
        bad = dict(good, axis_to_body=[[1.5, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        with open(cls.triad_file, "w") as f:
            yaml.safe_dump(bad, f)
        cls.bad = reload()
        cls.bad_response = rospy.get_rostime().to_nsec()
        shutil.copy(cls.original, cls.triad_file)  # as the launch found it, for a rerun

        util.wait_for(lambda: all(d.msg is not None and d.msg.data for d in done.values()),
                      "the three scenarios to end")
        # The last messages: every channel sample this test received has its output (the processors
        # have worked through their queues), then no message for 2 s and two diagnostics rounds.
        util.wait_for(lambda: all(cls.outputs[a].msg is not None and cls.channels[a].msg is not None and
                                  cls.outputs[a].msg.header.stamp == cls.channels[a].msg.header.stamp
                                  for a in AXES), "each processor's output of its last channel sample")
        quiet = [cls.imu, cls.triad_out] + list(cls.outputs.values()) + list(cls.axis_imu.values())
        cls.wait_quiet(quiet)
        for topic in list(cls.channels.values()) + list(cls.outputs.values()) + list(cls.axis_imu.values()) + [
                cls.imu, cls.triad_out]:
            topic.sub.unregister()
        cls.by_stamp = {a: {ns(o): o for o in cls.outputs[a].all if ns(o) != cls.stray_stamp} for a in AXES}
        cls.variance = {a: {ns(i): i.angular_velocity_covariance[8] for i in cls.axis_imu[a].all} for a in AXES}
        cls.triad_by_stamp = {ns(t): t for t in cls.triad_out.all}

    @classmethod
    def on_diagnostics(cls, msg):
        for s in msg.status:
            cls.statuses[s.name] = s
            cls.status_rounds[s.name] = cls.status_rounds.get(s.name, 0) + 1

    @classmethod
    def wait_quiet(cls, subscribers, quiet=2.0):
        """Until none of `subscribers` received a message for `quiet` s of wall time, then two more
        rounds of every diagnostic status (the counters after the last message)."""
        state = {"counts": None, "since": time.time()}

        def settled():
            counts = [s.count for s in subscribers]
            if counts != state["counts"]:
                state["counts"], state["since"] = counts, time.time()
            return time.time() - state["since"] >= quiet
        util.wait_for(settled, "the last outputs")
        rounds = dict(cls.status_rounds)
        util.wait_for(lambda: all(cls.status_rounds[n] >= r + 2 for n, r in rounds.items()),
                      "two rounds of every diagnostic status")

    def bias_at(self, stamp):
        """The bias in force at `stamp`: the triad swaps it between two samples it combines and says
        after which stamp, which is behind /clock by however late the pipeline runs."""
        return self.bias if stamp <= self.good_swap else self.new_bias

    def test_01_every_node_is_a_nodelet_of_one_manager(self):
        util.wait_for_service("/triad_manager/list")
        loaded = rospy.ServiceProxy("/triad_manager/list", NodeletList)().nodelets
        for name in ["/triad"] + ["/%s/%s" % (a, n) for a in AXES for n in ("driver_sim", "processor")]:
            self.assertIn(name, loaded)

    def test_02_the_imu_is_m_r_minus_bias_of_the_axes_own_outputs(self):
        imus = self.imu.all
        # 25 s of 200 Hz, less the gaps
        self.assertGreater(len(imus), 4000)
        checked = 0
        for m in imus:
            stamp = ns(m)
            self.assertEqual(m.header.frame_id, "imu_link")
            self.assertEqual(m.orientation_covariance[0], -1.0)
            self.assertEqual(m.linear_acceleration_covariance[0], -1.0)
            # what the message carries (docs/ros_api.md): no orientation, no acceleration, zeros
            self.assertEqual(vector(m.linear_acceleration).tolist(), [0.0, 0.0, 0.0])
            self.assertEqual((m.orientation.x, m.orientation.y, m.orientation.z, m.orientation.w), (0.0, 0.0, 0.0, 0.0))
            for a in AXES:
                self.assertIn(stamp, self.by_stamp[a], "an Imu at a stamp axis %s has no output for" % a)
            outs = [self.by_stamp[a][stamp] for a in AXES]
            self.assertTrue(all(o.flags & 3 == 0 for o in outs))
            if len({o.dt for o in outs}) > 1:
                continue  # an axis skipped the stamp before: combined over both intervals (test_04)
            r = np.array([o.rate for o in outs])
            bias = self.bias_at(stamp)
            if bias is not None:
                expected = self.m @ r - bias
                self.assertLess(np.max(np.abs(vector(m.angular_velocity) - expected)), 1e-12, stamp)
                checked += 1
            cov = np.array(m.angular_velocity_covariance).reshape(3, 3)
            self.assertTrue(np.array_equal(cov, cov.T), "covariance not symmetric at %d" % stamp)
            self.assertGreater(np.min(np.linalg.eigvalsh(cov)), 0.0)
            v = np.array([self.variance[a][stamp] for a in AXES])
            expected_cov = self.m @ np.diag(v) @ self.m.T
            self.assertLess(np.max(np.abs(cov - expected_cov)), 1e-12 * np.max(np.abs(expected_cov)), stamp)
        self.assertGreater(checked, 0.9 * len(imus))

    def test_03_no_imu_for_a_flagged_sample_and_one_for_every_other(self):
        imu_stamps = {ns(m): m for m in self.imu.all}
        flagged = [t for t in self.triad_out.all if t.flags & (FLAG_GAP | FLAG_RESET)]
        self.assertGreater(len(flagged), 0)
        for t in flagged:
            self.assertNotIn(ns(t), imu_stamps)
            self.assertEqual((t.delta_angle.x, t.delta_angle.y, t.delta_angle.z), (0.0, 0.0, 0.0))
        for t in self.triad_out.all:
            if t.flags & (FLAG_GAP | FLAG_RESET):
                continue
            self.assertIn(ns(t), imu_stamps)
            m = imu_stamps[ns(t)]
            self.assertEqual(vector(t.angular_velocity).tolist(), vector(m.angular_velocity).tolist())
            self.assertEqual(list(t.angular_velocity_covariance), list(m.angular_velocity_covariance))
            self.assertEqual(t.header.frame_id, "imu_link")

    def test_04_a_skipped_stamp_is_carried_and_a_gap_is_never_a_mix(self):
        # An output whose interval spans samples its processor dropped (y's 3 lost samples at 6 s, x's
        # and z's glitched stamps): the stamps it skipped are not published, and it is combined with
        # the other axes' increments over the same span: delta = M (sum of each axis's dalpha) - bias dt.
        spanning = {a: [s for s, o in self.by_stamp[a].items() if o.dt > 0.0075 and not o.flags & 1] for a in AXES}
        self.assertEqual(len(spanning["y"]), 1, spanning["y"])
        self.assertEqual(len(spanning["x"]), 1, "x's glitched sample at 4 s")
        self.assertEqual(len(spanning["z"]), 1, "z's glitched sample at 7 s")
        for a in AXES:
            for stamp in spanning[a]:
                o = self.by_stamp[a][stamp]
                t = self.triad_by_stamp.get(stamp)
                self.assertIsNotNone(t, "no triad sample at %d" % stamp)
                self.assertEqual(t.flags & (FLAG_GAP | FLAG_RESET), 0, stamp)
                self.assertAlmostEqual(t.dt, o.dt, delta=1e-12)
                start = stamp - int(round(o.dt * 1e9))
                sums = np.array([sum(p.dalpha for s, p in self.by_stamp[b].items() if start < s <= stamp)
                                 for b in AXES])
                skipped = [s for s in self.by_stamp["x" if a != "x" else "y"] if start < s < stamp]
                self.assertGreaterEqual(len(skipped), 1)
                for s in skipped:
                    self.assertNotIn(s, self.triad_by_stamp, "a skipped stamp published")
                bias = self.bias_at(stamp)
                self.assertLess(np.max(np.abs(vector(t.delta_angle) - (self.m @ sums - bias * o.dt))), 1e-12)
        # y's outage of 0.3 s: the stamps it lacks are gaps. y's session is the shortest (its table
        # reaches its rate soonest): after its last output the triad waits for it (max_wait), so the
        # stamps lost are those before.
        lost = []
        y_end = max(self.by_stamp["y"])
        for stamp in self.by_stamp["x"]:
            if stamp in self.by_stamp["z"] and stamp not in self.by_stamp["y"] and stamp < y_end and \
                    stamp not in spanning["x"] and stamp not in spanning["z"] and \
                    not any(s - int(round(self.by_stamp["y"][s].dt * 1e9)) < stamp < s for s in spanning["y"]):
                lost.append(stamp)
        self.assertGreaterEqual(len(lost), 50, "the scenario's outage on y (0.3 s)")
        for stamp in lost:
            self.assertIn(stamp, self.triad_by_stamp, "no triad sample at %d" % stamp)
            self.assertTrue(self.triad_by_stamp[stamp].flags & FLAG_GAP, stamp)
        # No stamp of the published output goes back, and nothing was reset.
        stamps = [ns(t) for t in self.triad_out.all]
        self.assertEqual(stamps, sorted(set(stamps)))
        self.assertFalse(any(t.flags & FLAG_RESET for t in self.triad_out.all))
        # Anywhere: an unflagged triad sample has all three axes, over one interval.
        for t in self.triad_out.all:
            if t.flags & (FLAG_GAP | FLAG_RESET):
                continue
            outs = [self.by_stamp[a].get(ns(t)) for a in AXES]
            self.assertTrue(all(outs), ns(t))
            self.assertAlmostEqual(t.dt, max(o.dt for o in outs), delta=1e-12)

    def test_05_each_axis_sees_its_table_rate(self):
        rates = np.array([vector(m.angular_velocity) for m in self.imu.all
                          if 3e9 < ns(m) <= self.good_swap])
        self.assertGreater(len(rates), 1000)
        axes = np.array([TABLE_RATES[a] + EARTH_VERTICAL for a in AXES])
        expected = self.m @ axes - self.bias
        self.assertLess(np.max(np.abs(rates.mean(axis=0) - expected)), 1e-3, (rates.mean(axis=0), expected))

    def test_06_reload_takes_a_good_file_and_refuses_a_bad_one(self):
        self.assertTrue(self.good.success, self.good.message)
        self.assertIn("loaded", self.good.message)
        self.assertFalse(self.bad.success, self.bad.message)
        self.assertIn("axis_to_body", self.bad.message)
        self.assertIn("kept the previous triad", self.bad.message)
        after = [m for m in self.imu.all if ns(m) > self.bad_response + MARGIN]
        self.assertGreater(len(after), 500)
        for m in after:
            r = np.array([self.by_stamp[a][ns(m)].rate for a in AXES])
            self.assertLess(np.max(np.abs(vector(m.angular_velocity) - (self.m @ r - self.new_bias))), 1e-12)

    def test_07_diagnostics_per_axis_and_of_the_triad(self):
        for a in AXES:
            self.assertIn("triad: axis %s" % a, self.statuses)
        for name in ("triad: combination", "triad: triad file", "triad: rate"):
            self.assertIn(name, self.statuses)
        values = {a: {kv.key: kv.value for kv in self.statuses["triad: axis %s" % a].values} for a in AXES}
        self.assertGreaterEqual(int(values["y"]["missing stamps"]), 50)
        self.assertEqual(int(values["x"]["missing stamps"]), 0)
        # The stray output on /x/output, dropped as out of order; nothing went backwards.
        self.assertEqual(int(values["x"]["dropped (out-of-order stamp)"]), 1)
        self.assertEqual(int(values["x"]["times went backwards"]), 0)
        c = {kv.key: kv.value for kv in self.statuses["triad: combination"].values}
        # One for every stamp an axis's output spans beyond its own (x's and z's glitches, y's lost samples).
        skipped = sum(int(round(o.dt / 0.005)) - 1 for a in AXES for o in self.by_stamp[a].values()
                      if o.dt > 0.0075 and not o.flags & 1)
        self.assertGreaterEqual(skipped, 1 + 1 + 2)
        self.assertEqual(int(c["stamps skipped by an axis (carried into the next)"]), skipped)
        self.assertEqual(values["x"]["topic"], "/x/output")
        f = {kv.key: kv.value for kv in self.statuses["triad: triad file"].values}
        self.assertEqual(f["triad file"], self.triad_file)
        self.assertEqual(f["frame_id"], "imu_link")
        self.assertEqual(int(f["refused reloads"]), 1)
        self.assertEqual(int(f["reloads"]), 1)
        c = {kv.key: kv.value for kv in self.statuses["triad: combination"].values}
        self.assertGreater(int(c["gaps"]), 50)

    def test_08_the_mounting_is_on_tf(self):
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)  # noqa: F841 (kept while it listens)
        # polled in wall time: the sim clock has stopped with the scenarios
        util.wait_for(lambda: buffer.can_transform("base_link", "imu_link", rospy.Time(0)), "base_link -> imu_link")
        t = buffer.lookup_transform("base_link", "imu_link", rospy.Time(0))
        self.assertAlmostEqual(t.transform.translation.x, 0.1)
        self.assertAlmostEqual(t.transform.translation.z, 0.2)

    def test_09_hrg_bag_process_gives_the_live_triad_output_bit_for_bit(self):
        recorded = os.path.join(self.work, "channels.bag")
        with rosbag.Bag(recorded, "w") as bag:
            # Recorded in the order they came, as rosbag record does: a glitched stamp keeps its place
            # (its record time is its predecessor's).
            messages = []
            for a in AXES:
                at = 0
                for m in self.channels[a].all:
                    at = ns(m) if abs(ns(m) - at) < 1e9 or at == 0 else at
                    messages.append((at, a, m))
            for at, a, m in sorted(messages, key=lambda x: x[:2]):
                bag.write("/%s/channels" % a, m, rospy.Time(nsecs=at))
        for a in AXES:  # the recording is complete: sequence numbers skip only where the scenario loses
            seqs = [m.header.seq for m in self.channels[a].all]
            self.assertEqual(seqs, sorted(seqs))
            if a != "y":
                self.assertEqual(seqs, list(range(seqs[0], seqs[0] + len(seqs))), a)
        offline = os.path.join(self.work, "offline.bag")
        p = subprocess.run([HRG_BAG, "process", recorded, "--triad", self.original, "--out", offline] +
                           ["--axis-params=%s=%s" % (a, self.params) for a in AXES],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=120)
        self.assertEqual(p.returncode, 0, p.stdout)
        with rosbag.Bag(offline) as bag:
            off = {ns(m): m for _, m, _ in bag.read_messages(topics=["/triad/output"])}
        live = [t for t in self.triad_out.all if ns(t) <= self.good_swap]  # offline: the original file
        self.assertGreater(len(live), 1000)
        for t in live:
            self.assertIn(ns(t), off)
            o = off[ns(t)]
            self.assertEqual(o.header.frame_id, t.header.frame_id)
            for f in TRIAD_FIELDS:
                self.assertTrue(same(getattr(o, f), getattr(t, f)), (ns(t), f))
            self.assertEqual(vector(o.delta_angle).tolist(), vector(t.delta_angle).tolist(), ns(t))
            self.assertEqual(vector(o.angular_velocity).tolist(), vector(t.angular_velocity).tolist(), ns(t))
            self.assertEqual(list(o.angular_velocity_covariance), list(t.angular_velocity_covariance), ns(t))


if __name__ == "__main__":
    rospy.init_node("triad_test")
    rostest.rosrun("hrg_gyro", "triad", Triad)
