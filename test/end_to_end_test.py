#!/usr/bin/env python3
"""Item 6 end to end, as nodelets: the demo pipeline calibrates from >= 500 ppm to < 1 ppm residual
nonlinearity measured on the verification profile, the estimates agree with the injected model
within a few standard errors, and the parameter file was replaced atomically (backup kept)."""
import os
import sys
import unittest

import rospy
import rostest
import yaml
from std_msgs.msg import String

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_test_util as util  # noqa: E402


class EndToEnd(unittest.TestCase):
    def test_calibration_removes_the_nonlinearity(self):
        summary = util.Latest("/session_monitor/summary", String)
        calibrator = util.Diagnostic("calibrator: calibration", ("wave samples", "turntable states", "runs"))
        # However long the session takes in wall time: fails only when it stops moving.
        util.wait_for(lambda: summary.msg, lambda: "the session summary (calibrator: %s)" % calibrator.message)
        s = yaml.safe_load(summary.msg.data)
        self.assertTrue(s["calibration_accepted"], s)
        self.assertTrue(s["calibration_written"], s)
        self.assertTrue(s["model_in_force"], "the calibrated model must apply before the verification")
        self.assertTrue(s["evaluation_ok"], s)
        self.assertEqual(s["after_samples"], s["verification_samples"], "outputs lost")
        self.assertEqual(s["before_samples"], s["verification_samples"], "outputs lost")
        self.assertGreater(s["before_ppm"], 500.0)
        self.assertLess(s["after_ppm"], 1.0)
        self.assertLess(s["worst_z"], 4.0, "an estimate is more than 4 standard errors from the injected model")
        self.assertLess(s["angle_error_after"], 1e-3 * s["angle_error_before"])
        params = rospy.get_param("~parameter_file")
        written = util.load_yaml(params)
        self.assertEqual(written["calibration"]["method"], "dual_rate")
        self.assertTrue(os.path.exists(params + ".bak"), "the previous file must be kept")
        self.assertEqual(util.load_yaml(params + ".bak")["calibration"]["method"], "none")


if __name__ == "__main__":
    rospy.init_node("end_to_end_test")
    rostest.rosrun("hrg_gyro", "end_to_end", EndToEnd)
