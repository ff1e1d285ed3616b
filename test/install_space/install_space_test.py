"""The package as a user installs it: run with only the install space sourced (run.sh).

Checks that nothing comes from the devel space or the source tree, that the nodes, tools,
libraries, headers, launch files, configuration and the nodelet plugins are installed and found
by rosrun/rospack, that a live pipeline (simulated gyro, processor and calibrator as nodelets in
one manager) runs from the installed launch files alone, and that catkin_lint finds nothing."""
import os
import subprocess
import sys
import unittest

import rosunit

SOURCE = os.environ["HRG_SOURCE_DIR"]
WORKSPACE = os.environ["HRG_WORKSPACE"]
PREFIX = os.path.join(WORKSPACE, "install")
RESULTS = os.environ["ROS_TEST_RESULTS_DIR"]


def run(*command, timeout=120):
    return subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                          timeout=timeout)


class InstallSpace(unittest.TestCase):
    def test_no_devel_space_or_source_tree_on_any_path(self):
        for var in ("CMAKE_PREFIX_PATH", "ROS_PACKAGE_PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "PATH",
                    "PKG_CONFIG_PATH"):
            value = os.environ.get(var, "")
            self.assertNotIn(os.path.join(WORKSPACE, "devel"), value, var)
            self.assertNotIn(os.path.join(WORKSPACE, "src"), value, var)
        self.assertIn(PREFIX, os.environ["CMAKE_PREFIX_PATH"])

    def test_package_found_in_the_install_space(self):
        p = run("rospack", "find", "hrg_gyro")
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertEqual(p.stdout.strip(), os.path.join(PREFIX, "share", "hrg_gyro"))

    def test_everything_a_user_runs_is_installed(self):
        for exe in ("driver_sim", "processor", "triad", "calibrator", "session_monitor", "gyrocompass", "hrg_bag",
                    "hrg_session",
                    "plot_calibration.py", "hrg_report.py", "hrg_batch.py", "hrg_gyro_core_bench",
                    "hrg_gyro_calibration_bench"):
            path = os.path.join(PREFIX, "lib", "hrg_gyro", exe)
            self.assertTrue(os.access(path, os.X_OK), path)
        for lib in ("libhrg_gyro_core.so", "libhrg_gyro_ros.so", "libhrg_gyro_nodelets.so"):
            self.assertTrue(os.path.isfile(os.path.join(PREFIX, "lib", lib)), lib)
        for rel in ("include/hrg_gyro/core/processing/gyro_processor.h", "include/hrg_gyro/ros/processor_ros.h",
                    "include/hrg_gyro/ChannelAmplitudes.h", "share/hrg_gyro/nodelet_plugins.xml",
                    "share/hrg_gyro/package.xml", "share/hrg_gyro/launch/processor.launch",
                    "share/hrg_gyro/launch/example_navigation_stack.launch", "share/hrg_gyro/config/processor.yaml",
                    "include/hrg_gyro/core/processing/triad_combiner.h", "include/hrg_gyro/ros/triad_ros.h",
                    "include/hrg_gyro/TriadOutput.h", "share/hrg_gyro/launch/triad.launch",
                    "share/hrg_gyro/launch/example_triad_stack.launch", "share/hrg_gyro/config/triad_node.yaml",
                    "share/hrg_gyro/config/triad.yaml", "include/hrg_gyro/core/alignment/gyrocompass.h",
                    "include/hrg_gyro/ros/gyrocompass_ros.h", "include/hrg_gyro/AlignmentResult.h",
                    "include/hrg_gyro/StartAlignment.h", "share/hrg_gyro/launch/gyrocompass.launch",
                    "share/hrg_gyro/config/gyrocompass.yaml", "share/hrg_gyro/config/scenarios/north_static.yaml",
                    "share/hrg_gyro/templates/alignment_report.html.j2",
                    "share/hrg_gyro/config/calibrator.yaml", "share/hrg_gyro/config/driver_sim.yaml",
                    "share/hrg_gyro/config/params_uncalibrated.yaml", "share/hrg_gyro/config/scenarios/dual_rate.yaml",
                    "share/hrg_gyro/config/report_spec.yaml", "share/hrg_gyro/templates/report.html.j2",
                    "share/hrg_gyro/templates/index.html.j2"):
            self.assertTrue(os.path.isfile(os.path.join(PREFIX, rel)), rel)

    def test_rosrun_hrg_bag_help(self):
        p = run("rosrun", "hrg_gyro", "hrg_bag", "--help")
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn("process", p.stdout)
        p = run("rosrun", "hrg_gyro", "hrg_session", "--help")
        self.assertEqual(p.returncode, 0, p.stdout)

    def test_plot_script_runs_from_the_install_space(self):
        # hrg_bag --plot runs it from beside itself; without arguments it prints its usage.
        p = run("/usr/bin/python3", os.path.join(PREFIX, "lib", "hrg_gyro", "plot_calibration.py"))
        self.assertIn("plot_calibration.py", p.stdout)
        self.assertNotIn("Traceback", p.stdout)

    def test_report_scripts_find_their_templates_and_hrg_bag_in_the_install_space(self):
        lib = os.path.join(PREFIX, "lib", "hrg_gyro")
        # The modules the scripts import from beside themselves.
        for module in ("hrg_output_file.py", "hrg_models.py", "hrg_report_validation.py", "hrg_report_figures.py",
                       "hrg_report_alignment.py"):
            self.assertTrue(os.path.isfile(os.path.join(lib, module)), module)
        p = run("/usr/bin/python3", "-c", "import sys; sys.path.insert(0, %r); import hrg_report, hrg_report_figures, hrg_report_alignment; "
                "print(hrg_report.find_template_dir()); print(hrg_report_figures.hrg_bag_executable())" % lib)
        self.assertEqual(p.stdout.split(), [os.path.join(PREFIX, "share", "hrg_gyro", "templates"),
                                            os.path.join(lib, "hrg_bag")], p.stdout)
        for script in ("hrg_report.py", "hrg_batch.py"):
            p = run("/usr/bin/python3", os.path.join(lib, script), "--help")
            self.assertEqual(p.returncode, 0, p.stdout)
            self.assertNotIn("Traceback", p.stdout)

    def test_nodelets_are_found(self):
        p = run("rospack", "plugins", "--attrib=plugin", "nodelet")
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn("hrg_gyro " + os.path.join(PREFIX, "share", "hrg_gyro", "nodelet_plugins.xml"), p.stdout)

    def test_live_pipeline_from_the_installed_launch_files(self):
        # rostest starts its own master; the .test file includes only installed launch files.
        test = os.path.join(SOURCE, "test", "install_space", "installed_pipeline.test")
        p = run("rostest", "--results-base-dir", RESULTS, test, timeout=300)
        self.assertEqual(p.returncode, 0, p.stdout[-4000:])
        self.assertIn("RESULT: SUCCESS", p.stdout)

    def test_catkin_lint_finds_nothing(self):
        # through the workspace's link, whose name is the package's (a checkout may be named otherwise)
        p = run("catkin_lint", "-W2", "--strict", os.path.join(WORKSPACE, "src", "hrg_gyro"))
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn("found 0 problems", p.stdout)


if __name__ == "__main__":
    rosunit.unitrun("hrg_gyro", "install_space", InstallSpace, sys.argv)
