#!/usr/bin/env python3
"""Two gyros in two namespaces of one nodelet manager: each processor runs on its own model file
(its K0 in its outputs), publishes in its own namespace and frame, and both run side by side."""
import os
import sys
import unittest

import rospy
import rostest
from nodelet.srv import NodeletList

from hrg_gyro.msg import GyroOutput, ModelInfo

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402


class TwoGyros(unittest.TestCase):
    def test_side_by_side(self):
        out = {g: util.Latest("/%s/output" % g, GyroOutput, keep_all=True) for g in ("gyro_a", "gyro_b")}
        model = {g: util.Latest("/%s/processor/model" % g, ModelInfo) for g in ("gyro_a", "gyro_b")}
        util.wait_for(lambda: all(o.count > 200 for o in out.values()) and all(m.msg for m in model.values()),
                      "outputs and models of both gyros")
        util.wait_for_service("/gyros_manager/list")
        loaded = rospy.ServiceProxy("/gyros_manager/list", NodeletList)().nodelets
        for name in ("/gyro_a/processor", "/gyro_b/processor", "/gyro_a/driver_sim", "/gyro_b/driver_sim"):
            self.assertIn(name, loaded)
        self.assertTrue(model["gyro_a"].msg.parameter_file.endswith("config/params_uncalibrated.yaml"))
        self.assertTrue(model["gyro_b"].msg.parameter_file.endswith("test/models/gyro_b.yaml"))
        self.assertEqual(model["gyro_a"].msg.k0, -0.56)
        self.assertEqual(model["gyro_b"].msg.k0, -0.5612)
        for g, k0 in (("gyro_a", -0.56), ("gyro_b", -0.5612)):
            msgs = out[g].all[-100:]
            self.assertTrue(all(m.header.frame_id == g + "_link" for m in msgs), g)
            # the uncalibrated-style models have no harmonics: K is K0 in every output
            self.assertTrue(all(m.scale_factor == k0 for m in msgs), (g, msgs[-1].scale_factor))


if __name__ == "__main__":
    rospy.init_node("two_gyros_test")
    rostest.rosrun("hrg_gyro", "two_gyros", TwoGyros)
