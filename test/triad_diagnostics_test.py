#!/usr/bin/env python3
"""The triad node's `combination` diagnostic when the axes' outputs arrive but combine into nothing
(test/triad_diagnostics.test). The test publishes /x/output, /y/output and /z/output itself, at
synthetic stamps 10 ms apart, in phases:

  1. x and y only: ERROR, naming axis z as the one that sent nothing;
  2. all three at the same stamps: OK "combining";
  3. z lacks every fifth stamp: WARN, gaps, naming z's missing stamps;
  4. z's stamps half a period off the others': ERROR, the stamps do not coincide;
  5. z stopped: ERROR, naming z.

Each verdict is awaited (any diagnostic report within the time limit that says it), so the pace of
the host decides nothing: a report whose window straddles two phases is simply not the one awaited.
"""
import os
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from hrg_gyro.msg import GyroOutput

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

AXES = ("x", "y", "z")
PERIOD_NS = 10000000  # 10 ms between stamps
T0_NS = 1000 * 1000000000


class Publisher(threading.Thread):
    """Publishes the three axes' outputs at the stamps the current phase asks for, about 100 per s."""

    def __init__(self):
        super(Publisher, self).__init__()
        self.daemon = True
        self.phase = "two_axes"
        self.stop = False
        self.pubs = {a: rospy.Publisher("/%s/output" % a, GyroOutput, queue_size=10000) for a in AXES}

    def output(self, stamp_ns):
        m = GyroOutput()
        m.header.stamp = rospy.Time(0, stamp_ns)
        m.dt = PERIOD_NS * 1e-9
        m.dalpha = 1e-4
        m.rate = m.dalpha / m.dt
        m.scale_factor = 1.0
        return m

    def run(self):
        k = 0
        while not self.stop and not rospy.is_shutdown():
            k += 1
            stamp = T0_NS + k * PERIOD_NS
            phase = self.phase
            self.pubs["x"].publish(self.output(stamp))
            self.pubs["y"].publish(self.output(stamp))
            if phase == "all":
                self.pubs["z"].publish(self.output(stamp))
            elif phase == "z_drops" and k % 5 != 0:
                self.pubs["z"].publish(self.output(stamp))
            elif phase == "z_shifted":
                self.pubs["z"].publish(self.output(stamp + PERIOD_NS // 2))
            time.sleep(0.01)


class TriadDiagnostics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.lock = threading.Lock()
        cls.reports = []  # (level, message, values) of "triad: combination", in arrival order
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        cls.publisher = Publisher()
        for p in cls.publisher.pubs.values():
            util.wait_for(lambda: p.get_num_connections() > 0, "the triad to subscribe to " + p.name)
        cls.publisher.start()

    @classmethod
    def tearDownClass(cls):
        cls.publisher.stop = True

    @classmethod
    def on_diagnostics(cls, msg):
        for s in msg.status:
            if s.name == "triad: combination":
                with cls.lock:
                    cls.reports.append((s.level, s.message, {kv.key: kv.value for kv in s.values}))

    def await_report(self, level, *texts, **kwargs):
        """The first report from now on at `level` whose message holds every text and none of `absent`:
        the first report after a change of phase may still count what the previous phase left (a stamp
        of x that z's shifted clock never matched), so the phase's own, steady report is waited for."""
        absent = kwargs.get("absent", ())
        with self.lock:
            start = len(self.reports)

        def found():
            with self.lock:
                for r in self.reports[start:]:
                    if r[0] == level and all(t in r[1] for t in texts) and not any(a in r[1] for a in absent):
                        return r
            return None
        try:
            r = util.wait_for(found, "a combination status at level %d saying %s" % (level, texts))
            print("[ measured ] level %d: %s" % (r[0], r[1]))
            return r
        except AssertionError:
            with self.lock:
                seen = sorted(set((r[0], r[1]) for r in self.reports[start:]))
            raise AssertionError("no combination status at level %d saying %s without %s; seen: %s" %
                                 (level, texts, absent, seen))

    def test_phases(self):
        # 1. Two axes publish: nothing can be combined, and the status says which axis is missing.
        r = self.await_report(DiagnosticStatus.ERROR, "nothing combined", "while axis outputs arrive",
                              "axis z sent nothing yet on /z/output", absent=("axis x", "axis y"))
        self.assertEqual(r[2]["combined"], "0")

        # 2. All three at one clock: every stamp combines.
        self.publisher.phase = "all"
        r = self.await_report(DiagnosticStatus.OK, "combining")
        self.assertGreater(int(r[2]["combined since the last report"]), 0)

        # 3. z loses a stamp in five: partial gaps, a warning naming z's missing stamps.
        self.publisher.phase = "z_drops"
        r = self.await_report(DiagnosticStatus.WARN, "samples are gaps", "axis z: ", "stamps missing",
                              absent=("axis x",))
        self.assertGreater(int(r[2]["combined since the last report"]), 0)

        # 4. z on a clock of its own: outputs of all three arrive, none share a stamp.
        self.publisher.phase = "z_shifted"
        r = self.await_report(DiagnosticStatus.ERROR, "nothing combined", "the axes' stamps do not coincide",
                              "axis z: ", "stamps missing")
        self.assertEqual(r[2]["combined since the last report"], "0")

        # 5. z stops: the others' outputs wait out max_wait and are emitted as gaps, never combined.
        self.publisher.phase = "two_axes"
        r = self.await_report(DiagnosticStatus.ERROR, "nothing combined", "axis z sent nothing for",
                              absent=("axis x", "axis y"))
        self.assertEqual(r[2]["combined since the last report"], "0")


if __name__ == "__main__":
    rospy.init_node("triad_diagnostics_test")
    rostest.rosrun("hrg_gyro", "triad_diagnostics", TriadDiagnostics)
