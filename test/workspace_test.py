"""The workspace `make build` leaves, as a newcomer uses it (run by `make test` after the install-space
check, with the devel space sourced).

Every `rosrun hrg_gyro PROGRAM` that the README and docs/ show finds exactly one program, without
a prompt or a warning (rosrun searches the package with `find -L`: a workspace reachable from the
package made it print "File system loop detected" and offer a menu of copies from devel/, build/
and install/), and `rosrun hrg_gyro hrg_bag --help` and `hrg_session --help` run as written."""
import glob
import os
import re
import subprocess
import sys
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rosrun(*args, timeout=60):
    # stdin closed: a menu would read end-of-file instead of waiting for a choice.
    return subprocess.run(["rosrun"] + list(args), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True, timeout=timeout)


def documented_programs():
    """The PROGRAM of every `rosrun hrg_gyro PROGRAM` in the README and docs/*.md."""
    found = set()
    for path in [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))):
        with open(path) as f:
            found.update(re.findall(r"rosrun hrg_gyro ([a-z][a-z0-9_.]*)", f.read()))
    return sorted(found)


class Workspace(unittest.TestCase):
    def test_the_docs_show_rosrun_commands(self):
        self.assertIn("hrg_bag", documented_programs())
        self.assertIn("hrg_session", documented_programs())

    def test_each_documented_program_is_found_once_without_a_warning(self):
        for program in documented_programs():
            # --prefix echo prints the program rosrun chose instead of running it.
            p = rosrun("--prefix", "echo", "hrg_gyro", program)
            self.assertEqual(p.returncode, 0, "%s: %s%s" % (program, p.stdout, p.stderr))
            self.assertEqual(p.stderr, "", program)
            chosen = p.stdout.split()
            self.assertEqual(len(chosen), 1, "%s: %r" % (program, p.stdout))
            self.assertTrue(os.access(chosen[0], os.X_OK), chosen[0])
            self.assertNotIn("/install/", chosen[0], "the devel space's program, not an install space's")

    def test_hrg_bag_help_runs_as_written(self):
        p = rosrun("hrg_gyro", "hrg_bag", "--help")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stderr, "")
        self.assertIn("usage: hrg_bag", p.stdout)
        for command in ("simulate", "process", "calibrate", "report", "batch", "import"):
            self.assertIn(command, p.stdout)

    def test_hrg_session_help_runs_as_written(self):
        p = rosrun("hrg_gyro", "hrg_session", "--help")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stderr, "")
        self.assertIn("--calibration", p.stdout)

    def test_the_workspace_is_not_reachable_from_the_package(self):
        package = subprocess.check_output(["rospack", "find", "hrg_gyro"], universal_newlines=True).strip()
        p = subprocess.run(["find", "-L", package, "-name", "setup.bash"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True)
        self.assertEqual(p.stderr, "")
        self.assertEqual(p.stdout, "", "a workspace below the package (%s)" % package)


if __name__ == "__main__":
    rosunit.unitrun("hrg_gyro", "workspace", Workspace, sys.argv)
