"""Shared helpers of the hrg_gyro integration tests (imported by the test nodes in this folder).

How a live test waits. A simulated session runs at whatever pace the host gives it: under sim time
driver_sim drives /clock and, when it is run late, lets the lag go (`~max_lag`), so on a loaded
machine the same session simply takes longer in wall time. A wait therefore has no wall-clock
budget: `wait_for` polls until its predicate holds and fails only when nothing moved for `stall`
seconds of wall time. What counts as moving (`progress()`): the simulated clock (when this node is
under sim time), every message a `Latest` of this node received, and any source passed to `watch`
(for example a node's diagnostic counters, which go on while a consumer works through its queue
after the driver is done). The rostest `time-limit` of a live test only catches a hang that no wait
of the test would see.

`wait_wall` is the fixed wall-clock budget, for properties that are wall time by definition (a
stall reported within `~stall_timeout` of wall time) and never for the progress of a session.
"""
import os
import threading
import time

import rospy
import yaml
from diagnostic_msgs.msg import DiagnosticArray

# Seconds of wall time without any progress after which a wait gives up. The slowest step that shows
# no progress is a node starting or fitting under load: measured at most a few tens of seconds with
# the machine at load 8 to 15 (docs/testing.md).
STALL = float(os.environ.get("HRG_TEST_STALL", "120"))

# Seconds this test node sleeps before it starts (0 unless set): run a live test with, say, 15 to
# check that its verdict does not hang on the test node starting before the session does.
time.sleep(float(os.environ.get("HRG_TEST_START_DELAY", "0")))

_sources = []
_latest = []


def watch(source):
    """Adds a progress source: a callable returning any comparable value that changes while the
    session (or a node working through it) moves on."""
    _sources.append(source)
    return source


def unwatch(source):
    """Removes a source added by `watch`."""
    _sources.remove(source)


def progress():
    """What this node can see of the session moving on: sim time, messages received, watched sources."""
    token = [sum(s.count for s in _latest)]
    if not rospy.rostime.is_wallclock():
        token.append(rospy.get_rostime().to_nsec())
    token.extend(source() for source in _sources)
    return tuple(token)


def describe_progress():
    parts = ["%d message(s) received" % sum(s.count for s in _latest)]
    if not rospy.rostime.is_wallclock():
        parts.append("sim time %.3f s" % rospy.get_rostime().to_sec())
    return ", ".join(parts)


def wait_for(predicate, what, stall=STALL):
    """Polls predicate() until it returns something true (returned); fails when nothing moved
    (`progress()`) for `stall` s of wall time. `what` may be a callable, evaluated on failure."""
    start = last_move = time.time()
    seen = progress()
    while not rospy.is_shutdown():
        value = predicate()
        if value:
            return value
        now = time.time()
        current = progress()
        if current != seen:
            seen, last_move = current, now
        elif now - last_move > stall:
            text = what() if callable(what) else what
            raise AssertionError("nothing moved for %.0f s of wall time (%s; %.0f s waited in all) waiting for %s" %
                                 (stall, describe_progress(), now - start, text))
        time.sleep(0.05)
    raise AssertionError("ROS shut down waiting for %s" % (what() if callable(what) else what))


def wait_wall(predicate, timeout, what):
    """Polls predicate() for at most `timeout` s of wall time: only for a wall-time property."""
    deadline = time.time() + timeout
    while time.time() < deadline and not rospy.is_shutdown():
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))


def wait_for_service(name, stall=STALL):
    """rospy.wait_for_service under the waiting rule above."""

    def available():
        try:
            rospy.wait_for_service(name, timeout=0.5)
            return True
        except rospy.ROSException:
            return False
    wait_for(available, "the service " + name, stall)


def sim_seconds_passed(seconds):
    """A predicate factory: true once `seconds` of sim time have passed since it was made."""
    start = rospy.get_time()
    return lambda: rospy.get_time() >= start + seconds


class Latest(object):
    """Keeps the latest message (and a count) of a topic; its messages count as progress."""

    def __init__(self, topic, msg_type, keep_all=False):
        self.msg = None
        self.all = [] if keep_all else None
        self.count = 0
        self.sub = rospy.Subscriber(topic, msg_type, self._on, queue_size=1000)
        _latest.append(self)

    def _on(self, msg):
        self.msg = msg
        self.count += 1
        if self.all is not None:
            self.all.append(msg)


class Diagnostic(object):
    """The latest values of the /diagnostics status whose name ends with `suffix`; the values of
    `progress_keys` (counters of a node's work) count as progress."""

    def __init__(self, suffix, progress_keys=()):
        self.suffix = suffix
        self.values = {}
        self.level = None
        self.message = None
        self._lock = threading.Lock()
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self._on, queue_size=100)
        if progress_keys:
            watch(lambda: tuple(self.get(k) for k in progress_keys))

    def _on(self, msg):
        for s in msg.status:
            if s.name.endswith(self.suffix):
                with self._lock:
                    self.values = dict((kv.key, kv.value) for kv in s.values)
                    self.level, self.message = s.level, s.message

    def get(self, key, default=None):
        with self._lock:
            return self.values.get(key, default)


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)
