#!/usr/bin/env python3
"""A calibration campaign: every bag of a folder calibrated in parallel, one report per bag.

  hrg_batch.py BAG_DIR OUT_DIR [--jobs N] [--timeout SECONDS] [--method M] [--params PRIOR.yaml]
               [--config CAL.yaml] [--spec LIMITS.yaml]

For each BAG_DIR/<name>.bag (sorted by name), in OUT_DIR/<name>/: `hrg_bag calibrate` writes
params.yaml (only when every quality gate passes) and report.yaml, then hrg_report.py writes
report.html from them and the bag (Allan deviation over the bag's longest rest), with the pass/fail
against --spec; log.txt keeps both tools' output. A bag whose folder would be named index.html (the
index's own name), ".", ".." or "" gets the first free name <name>_2, <name>_3, ... instead: the
index is always written. At most --jobs bags run at once (default: the number of cores). Each bag
has --timeout seconds (default 3600, 0 for no limit) for both tools; then its processes are killed
and its row says "timed out". A bag that fails (not a regular file, unreadable, refused by a gate,
out of specification, out of time) does not stop the others: its row in OUT_DIR/index.html says
why, and the index is written even when every bag fails.

Every file written here (log.txt, index.html; the tools write the others) goes through the package's
atomic writer (hrg_output_file.py): whole or not at all, nothing left behind on a full disk. No output
may be one of the inputs (--params, --config, --spec, a bag), by file identity.

Exit codes:
  0  every bag was calibrated and passed
  1  at least one bag did not (its row in the index says why)
  2  bad usage or input, nothing written: an option; BAG_DIR missing, not a folder or not listable;
     no .bag in it; a bad specification; an output that is one of the inputs, or an existing
     output that is not a regular file
  3  OUT_DIR could not be created or written, or the index could not be written
"""
import argparse
import concurrent.futures
import datetime
import math
import os
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import hrg_report  # noqa: E402  (beside this script, source and install space alike: its page templates)
import hrg_output_file  # noqa: E402
from hrg_models import one_line  # noqa: E402
from hrg_report_figures import hrg_bag_executable  # noqa: E402
from hrg_report_validation import ReportError, load_spec  # noqa: E402

INDEX = "index.html"
# Per-bag folder names that would be the index, OUT_DIR itself or its parent.
RESERVED_FOLDERS = {INDEX, "", ".", ".."}
BAG_OUTPUTS = ("params.yaml", "report.yaml", "report.html", "log.txt")
DEFAULT_TIMEOUT = 3600.0


def folder_names(names):
    """{bag name: its folder in OUT_DIR}: the name itself, or for a reserved one the first free
    <name>_2, <name>_3, ... (free of every other bag's folder too)."""
    taken = RESERVED_FOLDERS | set(names)
    folders = {}
    for name in names:
        if name not in RESERVED_FOLDERS:
            folders[name] = name
            continue
        k = 2
        while "%s_%d" % (name, k) in taken:
            k += 1
        folders[name] = "%s_%d" % (name, k)
        taken.add(folders[name])
    return folders


class TimedOut(Exception):
    pass


class Stopped(Exception):
    """The campaign is being interrupted: no new process is started."""


class Campaign:
    """The children of the running bags, each in a process group of its own so that a bag's whole
    tree (hrg_report runs hrg_bag allan) can be killed at its time limit or on an interrupt."""

    def __init__(self, args, hrg_bag, scratch):
        self.args, self.hrg_bag, self.scratch = args, hrg_bag, scratch
        self.lock = threading.Lock()
        self.running = set()
        self.stopping = False

    def run(self, cmd, deadline, log, env):
        """(exit code, output) of cmd; TimedOut once `deadline` (time.monotonic()) has passed."""
        log.append("$ %s\n" % " ".join(shlex.quote(c) for c in cmd))
        with self.lock:
            if self.stopping:
                raise Stopped()
            p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 text=True, errors="replace", env=env, start_new_session=True)
            self.running.add(p)
        try:
            try:
                out, _ = p.communicate(timeout=None if deadline is None else max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                self.kill(p)
                out, _ = p.communicate()
                log.append(out)
                raise TimedOut()
        finally:
            with self.lock:
                self.running.discard(p)
        log.append(out)
        return p.returncode, out

    @staticmethod
    def kill(p):
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def stop(self):
        with self.lock:
            self.stopping = True
            for p in self.running:
                self.kill(p)


def last_line(output, default):
    lines = [line for line in output.splitlines() if line.strip() and "%" not in line]  # not progress
    return one_line(lines[-1]) if lines else default


def calibrate_one(campaign, bag, name, folder, out_dir):
    """Calibrates one bag and writes its report and log; returns its row of the index."""
    args = campaign.args
    row = {"name": name, "bag": bag, "dir": folder, "calibration": "not run", "spec": None, "passed": False,
           "why": "", "report": None, "params": None, "log": None}
    # Checked before anything opens it: a FIFO named x.bag would block the reader for ever.
    try:
        st = os.stat(bag)
    except OSError as e:
        row["why"] = "cannot read the bag: %s" % e.strerror
        return row
    if not stat.S_ISREG(st.st_mode):
        row["why"] = "not a regular file: it is %s (not opened)" % hrg_output_file.kind_of(st.st_mode)
        return row
    work = os.path.join(out_dir, folder)
    try:
        os.makedirs(work, exist_ok=True)
    except OSError as e:
        row["why"] = "cannot create its folder %s: %s" % (work, e.strerror or e)
        return row
    # The tools' own temporary files (hrg_report's Allan deviation) in a folder of the bag's own,
    # removed afterwards even when they were killed.
    scratch = tempfile.mkdtemp(prefix=folder[:40] + ".", dir=campaign.scratch)
    env = dict(os.environ, TMPDIR=scratch)
    deadline = time.monotonic() + args.timeout if args.timeout > 0 else None
    log, step = [], "hrg_bag calibrate"
    try:
        params, report, html = (os.path.join(work, n) for n in BAG_OUTPUTS[:3])
        cmd = [campaign.hrg_bag, "calibrate", bag, "--out", params, "--report", report]
        for option in ("method", "params", "config"):
            if getattr(args, option):
                cmd += ["--" + option, getattr(args, option)]
        code, out = campaign.run(cmd, deadline, log, env)
        if code not in (0, 1) or not os.path.isfile(report):
            row["calibration"] = "failed"
            row["why"] = last_line(out, "hrg_bag calibrate exit %d" % code)
            return row
        row["calibration"] = "accepted" if code == 0 else "refused"
        if code == 0:
            row["params"] = folder + "/params.yaml"
        else:
            refused = [line for line in out.splitlines() if "REFUSED" in line]
            row["why"] = one_line(refused[0]) if refused else "refused by a quality gate"
        step = "hrg_report"
        cmd = [sys.executable, os.path.join(HERE, "hrg_report.py"), report, "--bag", bag, "--out", html,
               "--title", "Calibration report: " + name]
        if code == 0:
            cmd += ["--params", params]
        elif args.params:
            cmd += ["--params", args.params]  # refused: the rest is processed with the prior
        if args.spec:
            cmd += ["--spec", args.spec]
        q, qout = campaign.run(cmd, deadline, log, env)
        if q != 0:
            row["why"] = (row["why"] + "; " if row["why"] else "") + "report: " + last_line(qout, "exit %d" % q)
            return row
        row["report"] = folder + "/report.html"
        if args.spec:
            row["spec"] = "PASS" if "spec PASS" in qout else "FAIL"
            if row["spec"] == "FAIL" and not row["why"]:
                row["why"] = "out of specification (see the report)"
        row["passed"] = row["calibration"] == "accepted" and row["spec"] != "FAIL"
    except TimedOut:
        if step == "hrg_bag calibrate":
            row["calibration"] = "timed out"
        row["passed"] = False
        row["why"] = (row["why"] + "; " if row["why"] else "") + "timed out after %g s (in %s)" % (args.timeout,
                                                                                                  step)
        log.append("\nhrg_batch: %s timed out after %g s: killed\n" % (step, args.timeout))
        # The killed writers' temporaries, removed as the next write of those files would.
        for n in BAG_OUTPUTS[:3]:
            hrg_output_file.remove_stale_temporaries(os.path.join(work, n))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
        try:
            hrg_output_file.write_file_atomically(os.path.join(work, "log.txt"), "".join(log))
            row["log"] = folder + "/log.txt"
        except hrg_output_file.OutputWriteError as e:
            row["passed"] = False
            row["why"] = (row["why"] + "; " if row["why"] else "") + "log.txt not written: %s" % one_line(e)
    return row


def failed_row(name, folder, bag, why):
    return {"name": name, "bag": bag, "dir": folder, "calibration": "failed", "spec": None, "passed": False,
            "why": why, "report": None, "params": None, "log": None}


def main(argv):
    parser = argparse.ArgumentParser(prog="hrg_batch.py", description=__doc__.split("\n\n")[0],
                                     epilog="Exit 0 every bag passed, 1 at least one did not, 2 bad usage or "
                                     "input, 3 OUT_DIR or the index could not be written.")
    parser.add_argument("bag_dir", help="folder of .bag files")
    parser.add_argument("out_dir", help="output folder (created)")
    parser.add_argument("--jobs", type=int, default=len(os.sched_getaffinity(0)),
                        help="bags at once (default: the cores this process may use, as nproc counts them)")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT, metavar="SECONDS",
                        help="time limit of one bag, calibration and report together; then its processes are "
                        "killed and its row says it timed out (default %g s; 0: no limit)" % DEFAULT_TIMEOUT)
    parser.add_argument("--method", help="calibration method (hrg_bag calibrate --method)")
    parser.add_argument("--params", help="prior parameter file")
    parser.add_argument("--config", help="calibrator settings YAML")
    parser.add_argument("--spec", metavar="LIMITS.yaml", help="specification YAML for the pass/fail")
    args = parser.parse_args(argv[1:])
    try:
        return run(args)
    except KeyboardInterrupt:
        sys.stderr.write("hrg_batch: interrupted: the running bags were killed, the index not written\n")
        return 130
    except Exception as e:  # last resort: a one-line error, never a traceback
        sys.stderr.write("hrg_batch: unexpected %s: %s\n" % (type(e).__name__, one_line(e)))
        return 2


def usage_error(message):
    sys.stderr.write("hrg_batch: %s\n" % message)
    return 2


def run(args):
    if args.jobs < 1:
        return usage_error("--jobs must be at least 1")
    if not (args.timeout >= 0 and math.isfinite(args.timeout)):
        return usage_error("--timeout must be a number of seconds >= 0 (0: no limit), not %s" % args.timeout)
    if not os.path.isdir(args.bag_dir):
        return usage_error("%s is not a folder" % args.bag_dir)
    try:
        names = os.listdir(args.bag_dir)
    except OSError as e:
        return usage_error("cannot list the bag folder %s: %s" % (args.bag_dir, e.strerror or e))
    for option in ("params", "config", "spec"):
        path = getattr(args, option)
        if not path:
            continue
        try:
            st = os.stat(path)
        except OSError as e:
            return usage_error("--%s %s: %s" % (option, path, "no such file" if isinstance(e, FileNotFoundError)
                                                else e.strerror))
        if not stat.S_ISREG(st.st_mode):
            return usage_error("--%s %s is %s, not a regular file" %
                               (option, path, hrg_output_file.kind_of(st.st_mode)))
        setattr(args, option, os.path.abspath(path))
    try:
        if args.spec:
            load_spec(args.spec)  # a bad specification is refused once, before any work
        hrg_bag = hrg_bag_executable()
    except ReportError as e:
        return usage_error(e)
    bag_names = sorted(n[:-len(".bag")] for n in names if n.endswith(".bag"))
    if not bag_names:
        return usage_error("no .bag file in %s" % args.bag_dir)
    bags = {n: os.path.abspath(os.path.join(args.bag_dir, n + ".bag")) for n in bag_names}
    folders = folder_names(bag_names)
    out_dir = os.path.abspath(args.out_dir)
    index = os.path.join(out_dir, INDEX)
    outputs = [index] + [os.path.join(out_dir, folders[n], f) for n in bag_names for f in BAG_OUTPUTS]
    inputs = [getattr(args, o) for o in ("params", "config", "spec")] + [bags[n] for n in bag_names]
    try:
        hrg_output_file.check_output_paths(inputs, outputs)
    except hrg_output_file.PathRefused as e:
        return usage_error("refused: %s" % e)

    # The output folder, and that the index can be written there, before hours of calibration.
    try:
        os.makedirs(out_dir, exist_ok=True)
    except FileExistsError:
        sys.stderr.write("hrg_batch: cannot create the output folder %s: it exists and is not a folder\n" %
                         args.out_dir)
        return 3
    except OSError as e:
        sys.stderr.write("hrg_batch: cannot create the output folder %s: %s\n" % (args.out_dir, e.strerror or e))
        return 3
    try:
        hrg_output_file.AtomicOutputFile(index).discard()
    except hrg_output_file.OutputWriteError as e:
        sys.stderr.write("hrg_batch: cannot write in the output folder %s: %s\n" % (args.out_dir, e))
        return 3

    scratch = tempfile.mkdtemp(prefix="hrg_batch.")
    campaign = Campaign(args, hrg_bag, scratch)
    rows = []
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs)
    try:
        futures = {pool.submit(calibrate_one, campaign, bags[n], n, folders[n], out_dir): n for n in bag_names}
        for future in concurrent.futures.as_completed(futures):
            name = futures[future]
            try:
                row = future.result()
            except Exception as e:  # one bag's unexpected failure must not end the campaign
                row = failed_row(name, folders[name], bags[name], "%s: %s" % (type(e).__name__, one_line(e)))
            rows.append(row)
            print("hrg_batch: %-24s %-9s %s %s" % (row["name"], row["calibration"],
                                                   "PASS" if row["passed"] else "FAIL", row["why"]), flush=True)
    except BaseException:  # KeyboardInterrupt, SIGTERM: no bag left running behind
        campaign.stop()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    finally:
        pool.shutdown(wait=True)
        shutil.rmtree(scratch, ignore_errors=True)
    rows.sort(key=lambda r: r["name"])
    passed = sum(1 for r in rows if r["passed"])
    html = hrg_report.render("index.html.j2", rows=rows, passed=passed, total=len(rows),
                             spec=os.path.basename(args.spec) if args.spec else None,
                             bag_dir=os.path.abspath(args.bag_dir),
                             generated=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"))
    try:
        hrg_output_file.write_file_atomically(index, html)
    except hrg_output_file.OutputWriteError as e:
        sys.stderr.write("hrg_batch: the index was not written: %s\n" % e)
        return 3
    print("hrg_batch: %d of %d passed; index in %s" % (passed, len(rows), index))
    return 0 if passed == len(rows) else 1


if __name__ == "__main__":
    # SIGTERM unwinds like an interrupt: the running bags are killed, temporaries removed.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    sys.exit(main(sys.argv))
