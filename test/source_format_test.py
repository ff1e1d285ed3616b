"""Every C++ file of the repository is formatted as .clang-format says (run by `make test`).

A file that differs is listed with the first lines of the difference; `clang-format -i FILE` fixes it."""
import os
import subprocess
import sys
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class SourceFormat(unittest.TestCase):
    def test_every_cpp_file_is_clang_formatted(self):
        files = subprocess.check_output(["git", "ls-files", "*.cpp", "*.h"], cwd=ROOT, universal_newlines=True).split()
        self.assertGreater(len(files), 100)
        differ = []
        for f in files:
            p = subprocess.run(["clang-format", "--style=file", "--dry-run", "--Werror", f], cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
            if p.returncode != 0:
                differ.append("%s:\n%s" % (f, "\n".join(p.stdout.splitlines()[:6])))
        self.assertEqual(differ, [], "not clang-formatted (clang-format -i FILE):\n" + "\n".join(differ))


if __name__ == "__main__":
    rosunit.unitrun("hrg_gyro", "source_format", SourceFormat, sys.argv)
