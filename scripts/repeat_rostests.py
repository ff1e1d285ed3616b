#!/usr/bin/env python3
"""Runs rostests of the package again and again, alone or beside a CPU load, and tells which passed,
how long each took and the figures they printed: the check that a live test's verdict does not follow
the host's pace (docs/testing.md, "A verdict must not follow the host's pace").

  scripts/repeat_rostests.py calibration_field --runs 20
  scripts/repeat_rostests.py calibration_field --runs 10 --load 2 --grep 'field live'
  scripts/repeat_rostests.py --all-live --runs 3 --load 2

Each run gets a fresh work directory (the build's hrg_gyro_test_work target, as `make test` does) and
its own result file; a test's printed lines matching --grep are shown per run. --load N starts N busy
loops (one process each) for the runs. Needs a built workspace (`make test` or `make build` and
`catkin_make tests`); --workspace defaults to the checkout's .ws. Exits 1 when any run failed.
"""
import argparse
import glob
import multiprocessing
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Rostests whose nodes do not run a session (a gtest with a master checks start-up parameters).
NOT_LIVE = {"parameter_templates", "triad_calibrator_parameters", "triad_node_parameters", "gyrocompass_parameters"}


def busy():
    while True:
        pass


def live_tests():
    names = sorted(os.path.splitext(os.path.basename(p))[0] for p in glob.glob(os.path.join(ROOT, "test", "*.test")))
    return [n for n in names if n not in NOT_LIVE]


def read_result(directory, pattern):
    """(tests, failures + errors, the printed lines matching pattern, first failure text) of one run's
    result files: rostest's summary (rostest-*.xml) and its test nodes' own (rosunit-*.xml)."""
    summaries = glob.glob(os.path.join(directory, "hrg_gyro", "rostest-*.xml"))
    if not summaries:
        return 0, 1, [], "no result file"
    tests = bad = 0
    lines, failure = [], ""
    for path in summaries + glob.glob(os.path.join(directory, "hrg_gyro", "rosunit-*.xml")):
        root = ET.parse(path).getroot()
        suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
        # rostest's summary counts its test nodes (one failed node is one failure); the nodes' own
        # files count their cases: a run is bad if either says so.
        if os.path.basename(path).startswith("rostest-"):
            tests += sum(int(s.get("tests", 0)) for s in suites)
        bad += sum(int(s.get("failures", 0)) + int(s.get("errors", 0)) for s in suites)
        for element in root.iter():
            if element.tag in ("failure", "error") and not failure:
                text = (element.get("message") or element.text or element.tag).strip().splitlines()
                failure = text[0][:300] if text else element.tag
            if element.tag == "system-out" and element.text and pattern:
                lines += [l for l in element.text.splitlines() if re.search(pattern, l)]
    return tests, bad, lines, failure


def run_once(workspace, test, results_dir, pattern):
    build = os.path.join(workspace, "build")
    subprocess.run(["make", "-s", "-C", build, "hrg_gyro_test_work"], check=True, stdout=subprocess.DEVNULL)
    work = os.path.join(build, "hrg_gyro", "test_work")
    directory = tempfile.mkdtemp(prefix=test + "_", dir=results_dir)
    command = ("source %s/devel/setup.bash && rostest --results-base-dir %s hrg_gyro %s.test work_dir:=%s" %
               (workspace, directory, test, work))
    env = dict(os.environ, PATH="/usr/bin:/bin:" + os.environ.get("PATH", ""))
    start = time.time()
    subprocess.run(["bash", "-c", command], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    seconds = time.time() - start
    return (seconds,) + read_result(directory, pattern)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tests", nargs="*", help="test names (test/NAME.test)")
    parser.add_argument("--all-live", action="store_true", help="every rostest that runs a session")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--load", type=int, default=0, help="busy loops beside the runs")
    parser.add_argument("--grep", default="", help="show each run's printed lines matching this pattern")
    parser.add_argument("--workspace", default=os.path.join(ROOT, ".ws"))
    args = parser.parse_args()
    tests = live_tests() if args.all_live else args.tests
    if not tests:
        parser.error("name a test or give --all-live")
    results_dir = tempfile.mkdtemp(prefix="hrg_repeat_")
    loads = [multiprocessing.Process(target=busy, daemon=True) for _ in range(args.load)]
    for p in loads:
        p.start()
    failed = 0
    try:
        for test in tests:
            for k in range(1, args.runs + 1):
                seconds, count, bad, lines, failure = run_once(args.workspace, test, results_dir, args.grep)
                failed += bad > 0
                print("%-32s run %2d  %s  %6.1f s  %d tests%s" % (test, k, "FAIL" if bad else "ok  ", seconds, count,
                                                                  ("  " + failure) if bad else ""), flush=True)
                for line in lines:
                    print("    " + line.strip(), flush=True)
    finally:
        for p in loads:
            p.terminate()
    print("%d failed run(s); load %d busy loop(s); result files in %s" % (failed, args.load, results_dir))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
