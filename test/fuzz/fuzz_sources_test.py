"""The fuzz build compiles the whole core library (run by `make test`, which has no clang).

test/fuzz/CMakeLists.txt takes the core's sources from the package's add_library list and stops
when that list and the concept folders disagree. This configures it in its check-only mode on the
checkout (it must find every source) and on copies of the layout with one source too many, one
too few and a list it cannot read (each must fail, naming the difference): a fuzz build that lost
its sources once went unnoticed because nothing configured it."""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def configure(package_root, build):
    return subprocess.run(["cmake", "-S", os.path.join(package_root, "test", "fuzz"), "-B", build,
                           "-DHRG_FUZZ_CHECK_SOURCES_ONLY=ON"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True)


def listed_sources(cmake_text):
    block = re.search(r"add_library\(\$\{PROJECT_NAME\}_core\s([^)]*)\)", cmake_text)
    return re.findall(r"src/core/[a-z_]+/(?:[a-z_]+/)?[a-z_0-9]+\.cpp", block.group(1)) if block else []


class FuzzSources(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="hrg_fuzz_sources.")
        with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
            self.cmake = f.read()
        self.sources = listed_sources(self.cmake)

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def fake_package(self, cmake_text, sources):
        """A copy of the layout: the package CMakeLists given, the fuzz CMakeLists, empty sources."""
        root = os.path.join(self.tmp, "package")
        shutil.rmtree(root, ignore_errors=True)
        os.makedirs(os.path.join(root, "test", "fuzz"))
        shutil.copy(os.path.join(ROOT, "test", "fuzz", "CMakeLists.txt"), os.path.join(root, "test", "fuzz"))
        with open(os.path.join(root, "CMakeLists.txt"), "w") as f:
            f.write(cmake_text)
        for s in sources + ["src/core/common/common_test.cpp", "src/core/integration/any_test.cpp",
                            "src/core/testing/helper.cpp",
                            "src/core/calibration/triad/triad_any_test.cpp"]:  # never part of the library
            os.makedirs(os.path.dirname(os.path.join(root, s)), exist_ok=True)
            open(os.path.join(root, s), "w").close()
        return root

    def test_the_checkout_configures_with_every_core_source(self):
        self.assertGreater(len(self.sources), 40)
        p = configure(ROOT, os.path.join(self.tmp, "build"))
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn("core sources: %d" % len(self.sources), p.stdout)

    def test_a_source_missing_from_the_list_stops_the_configuration(self):
        root = self.fake_package(self.cmake, self.sources + ["src/core/model/new_module.cpp"])
        p = configure(root, os.path.join(self.tmp, "build"))
        self.assertNotEqual(p.returncode, 0, p.stdout)
        self.assertIn("src/core/model/new_module.cpp", p.stdout)

    def test_a_source_of_a_sub_folder_missing_from_the_list_stops_the_configuration(self):
        root = self.fake_package(self.cmake, self.sources + ["src/core/calibration/triad/new_module.cpp"])
        p = configure(root, os.path.join(self.tmp, "build"))
        self.assertNotEqual(p.returncode, 0, p.stdout)
        self.assertIn("src/core/calibration/triad/new_module.cpp", p.stdout)

    def test_a_listed_source_missing_from_the_folders_stops_the_configuration(self):
        root = self.fake_package(self.cmake, self.sources[1:])
        p = configure(root, os.path.join(self.tmp, "build"))
        self.assertNotEqual(p.returncode, 0, p.stdout)
        self.assertIn(self.sources[0], p.stdout)

    def test_an_unreadable_list_stops_the_configuration(self):
        root = self.fake_package(self.cmake.replace("add_library(${PROJECT_NAME}_core", "add_library(core_renamed"),
                                 self.sources)
        p = configure(root, os.path.join(self.tmp, "build"))
        self.assertNotEqual(p.returncode, 0, p.stdout)
        self.assertIn("no core source found", p.stdout)


if __name__ == "__main__":
    rosunit.unitrun("hrg_gyro", "fuzz_sources", FuzzSources, sys.argv)
