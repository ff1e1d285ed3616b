#!/usr/bin/env python3
"""The gyrocompass when its input stops (test/gyrocompass_stall.test): this node is the triad. It
publishes `triad/output` of a level body at rest (true heading 30 deg, latitude 0.9 rad, white angle
noise 1e-7 rad per sample, 100 Hz, at about that pace in wall time) when it chooses, which is the point: a stream that stops
(a bag paused, a dead triad node) must show in the diagnostics within `~stall_timeout` of wall time,
not leave the node "aligning" forever.

- ~align, 0.5 s of stamps, then nothing: the `gyrocompass` diagnostic turns ERROR "aligning, input
  stalled: no /triad/output", with the quiet seconds;
- ~align again: it replaces the stalled alignment (not refused as "an alignment runs"), and the
  stream resumed fills its window: accepted, the heading within 4 of its sigmas of the truth;
- the hold then: OK "holding" while the triad publishes; ERROR "holding, input stalled" once it stops;
  OK again while it publishes again (the stamps continuous: the attitude is not lost), ERROR again."""
import math
import os
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from hrg_gyro.msg import AlignmentResult, TriadOutput
from hrg_gyro.srv import StartAlignment

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402

EARTH_RATE = 7.2921150e-5  # rad/s
LATITUDE = 0.9  # rad, the node's ~latitude
HEADING = 30.0  # deg, true, clockwise from North
PERIOD = 0.01  # s between samples
NOISE = 1e-7  # rad per sample, the node's ~noise/angle_white_noise
WINDOW = 6.0  # s of stamps, the node's ~duration
STALL_TIMEOUT = 0.5  # s of wall time, the node's ~stall_timeout
# How long a stall may take to show: the timeout, a diagnostic period (1 s) and a margin for a busy host.
STALL_SHOWS_WITHIN = STALL_TIMEOUT + 1.0 + 10.0


class Triad(object):
    """A level triad at rest: increments of the Earth's rate in the body frame, plus white angle noise."""

    def __init__(self):
        self.pub = rospy.Publisher("/triad/output", TriadOutput, queue_size=10000)
        yaw = math.radians(90.0 - HEADING)  # body x from East, counter-clockwise
        enu = EARTH_RATE * np.array([0.0, math.cos(LATITUDE), math.sin(LATITUDE)])
        c, s = math.cos(yaw), math.sin(yaw)
        self.rate = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]).dot(enu)  # R^T w_enu
        self.rng = np.random.default_rng(7)
        self.previous = np.zeros(3)
        self.stamp = 1000.0

    def publish(self, seconds):
        """`seconds` of stamps at their own pace in wall time, as a live triad publishes them."""
        for _ in range(int(round(seconds / PERIOD))):
            self.stamp += PERIOD
            noise = NOISE * self.rng.standard_normal(3)
            delta = self.rate * PERIOD + noise - self.previous
            self.previous = noise
            m = TriadOutput()
            m.header.stamp = rospy.Time.from_sec(self.stamp)
            m.header.frame_id = "base_link"
            m.dt = PERIOD
            m.delta_angle.x, m.delta_angle.y, m.delta_angle.z = delta
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = delta / PERIOD
            variance = 2.0 * (NOISE / PERIOD) ** 2
            m.angular_velocity_covariance = [variance, 0, 0, 0, variance, 0, 0, 0, variance]
            self.pub.publish(m)
            time.sleep(PERIOD)


class GyrocompassStall(unittest.TestCase):
    def setUp(self):
        self.statuses = []  # (wall time received, name, status)
        self.lock = threading.Lock()
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        self.result = util.Latest("/alignment/result", AlignmentResult)
        self.triad = Triad()
        util.wait_for(lambda: self.triad.pub.get_num_connections() > 0, "the gyrocompass to listen to /triad/output")
        rospy.wait_for_service("/gyrocompass/align")
        self.align = rospy.ServiceProxy("/gyrocompass/align", StartAlignment)

    def on_diagnostics(self, msg):
        now = time.time()
        with self.lock:
            for s in msg.status:
                if s.name.startswith("gyrocompass: "):
                    self.statuses.append((now, s.name[len("gyrocompass: "):], s))

    def seen(self, name, level, text, since, until=None):
        """A status `name` at `level` saying `text`, received in [since, until] of wall time, or None."""
        with self.lock:
            for t, n, s in self.statuses:
                if n == name and s.level == level and text in s.message and t >= since and (until is None or t <= until):
                    return s
        return None

    def stall_shows(self, name, text, since):
        """The ERROR `name` saying `text`, received after `since`: within STALL_SHOWS_WITHIN s of wall
        time (a stall is a wall-time property by definition)."""
        return util.wait_wall(lambda: self.seen(name, DiagnosticStatus.ERROR, text, since), STALL_SHOWS_WITHIN,
                              "%s ERROR saying %r" % (name, text))

    def test_a_stopped_stream_shows_and_the_next_align_replaces_it(self):
        reply = self.align(2.0 * WINDOW, "")
        self.assertTrue(reply.success, reply.message)
        self.triad.publish(0.5)
        stopped = time.time()
        s = self.stall_shows("gyrocompass", "aligning, input stalled: no /triad/output", stopped)
        quiet = float({kv.key: kv.value for kv in s.values}["seconds without gyro input"])
        print("stalled alignment: %r after %.1f s of wall time (quiet %.2f s)" % (s.message, time.time() - stopped, quiet))
        self.assertGreater(quiet, STALL_TIMEOUT)

        reply = self.align(WINDOW, "")
        self.assertTrue(reply.success, "a stalled alignment must be replaced: " + reply.message)
        self.triad.publish(WINDOW + 0.5)
        r = util.wait_for(lambda: self.result.msg, "the alignment's result")
        self.assertTrue(r.accepted, "%s: %s" % (r.gate, r.reason))
        error = (r.heading_deg - HEADING + 180.0) % 360.0 - 180.0
        print("heading %.5f +- %.5f deg against %.1f: %.2f sigma" % (r.heading_deg, r.heading_sigma_deg, HEADING,
                                                                     error / r.heading_sigma_deg))
        self.assertLess(abs(error), 4.0 * r.heading_sigma_deg)
        self.assertAlmostEqual(r.seconds, WINDOW, delta=0.05)

        # The hold: OK while the triad publishes (longer than a diagnostic period), ERROR once it stops,
        # OK again while it publishes again (the stamps continuous: the attitude is not lost).
        for turn in ("first", "resumed"):
            start = time.time()
            self.triad.publish(2.5)
            with self.lock:
                received = [(round(t - start, 2), s.level, s.message) for t, n, s in self.statuses
                            if n == "attitude hold" and t >= start]
            self.assertIsNotNone(self.seen("attitude hold", DiagnosticStatus.OK, "holding", start, time.time()),
                                 "the hold OK while the triad publishes (%s): %s" % (turn, received))
            s = self.stall_shows("attitude hold", "holding, input stalled: no /triad/output", time.time())
            print("stalled hold (%s): %r" % (turn, s.message))

if __name__ == "__main__":
    rospy.init_node("gyrocompass_stall_test")
    rostest.rosrun("hrg_gyro", "gyrocompass_stall", GyrocompassStall)
