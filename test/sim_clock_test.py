#!/usr/bin/env python3
"""driver_sim drives /clock with every output sample by default (its template says clock_period:
auto), so a consumer's timer under sim time runs at its own rate: a 50 Hz timer fires 50 times per
simulated second."""
import os
import sys
import threading
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock

from hrg_gyro.msg import ChannelAmplitudes

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402


class SimClock(unittest.TestCase):
    def test_a_50_hz_timer_runs_at_50_hz_with_a_clock_per_sample(self):
        lock = threading.Lock()
        state = {"clocks": 0, "channels": 0, "ticks": 0}

        def on_clock(_):
            with lock:
                state["clocks"] += 1

        def on_channels(_):
            with lock:
                state["channels"] += 1

        rospy.Subscriber("/clock", Clock, on_clock, queue_size=1000)
        # The driver starts once this test listens to its channels.
        channels_sub = rospy.Subscriber("/gyro/channels", ChannelAmplitudes, on_channels, queue_size=1000)
        util.watch(lambda: state["channels"])
        # The session starts at 1 s; let it run (however long the session takes in wall time).
        util.wait_for(lambda: rospy.get_rostime() > rospy.Time(2.0), "2 s of sim time")
        with lock:
            base = dict(state)

        def on_tick(_):
            with lock:
                state["ticks"] += 1

        start = rospy.get_rostime()
        timer = rospy.Timer(rospy.Duration(0.02), on_tick)
        util.wait_for(lambda: rospy.get_rostime() >= start + rospy.Duration(10.0), "10 s more of sim time")
        timer.shutdown()
        channels_sub.unregister()
        with lock:
            ticks, clocks = state["ticks"], state["clocks"] - base["clocks"]
            channels = state["channels"] - base["channels"]
        rospy.loginfo("10 s of sim time: %d timer ticks, %d /clock, %d channel samples", ticks, clocks, channels)
        self.assertGreater(channels, 1800)
        self.assertGreaterEqual(clocks, 0.95 * channels, "a /clock message with every 200 Hz sample")
        self.assertGreaterEqual(ticks, 490, "the 50 Hz timer throttled by the clock")
        self.assertLessEqual(ticks, 510)


if __name__ == "__main__":
    rospy.init_node("sim_clock_test")
    rostest.rosrun("hrg_gyro", "sim_clock", SimClock)
