"""Shared helpers of the hrg_gyro integration tests (imported by the test nodes in this folder)."""
import time

import rospy
import yaml


def wait_for(predicate, timeout, what):
    """Polls predicate() in wall time (sim time may be stopped or racing) until true or timeout."""
    deadline = time.time() + timeout
    while time.time() < deadline and not rospy.is_shutdown():
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))


class Latest(object):
    """Keeps the latest message (and a count) of a topic."""

    def __init__(self, topic, msg_type, keep_all=False):
        self.msg = None
        self.all = [] if keep_all else None
        self.count = 0
        self.sub = rospy.Subscriber(topic, msg_type, self._on, queue_size=1000)

    def _on(self, msg):
        self.msg = msg
        self.count += 1
        if self.all is not None:
            self.all.append(msg)


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)
