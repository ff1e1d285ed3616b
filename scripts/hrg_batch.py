#!/usr/bin/env python3
"""A calibration campaign: every bag of a folder calibrated in parallel, one report per bag.

  hrg_batch.py BAG_DIR OUT_DIR [--jobs N] [--method M] [--params PRIOR.yaml] [--config CAL.yaml]
               [--spec LIMITS.yaml]

For each BAG_DIR/<name>.bag (sorted by name), in OUT_DIR/<name>/: `hrg_bag calibrate` writes
params.yaml (only when every quality gate passes) and report.yaml, then hrg_report.py writes
report.html from them and the bag (Allan deviation over the bag's longest rest), with the pass/fail
against --spec; log.txt keeps both tools' output. At most --jobs bags run at once (default: the
number of cores). A bag that fails (unreadable, refused by a gate, out of spec) does not stop the
others: its row in OUT_DIR/index.html says why.

Exit 0 when every bag was calibrated and passed, 1 when at least one did not, 2 bad usage.
"""
import argparse
import concurrent.futures
import datetime
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import hrg_report  # noqa: E402  (beside this script, source and install space alike)


def calibrate_one(bag, out_dir, args):
    """Calibrates one bag and writes its report; returns its row of the index."""
    name = os.path.splitext(os.path.basename(bag))[0]
    work = os.path.join(out_dir, name)
    os.makedirs(work, exist_ok=True)
    params, report, html = (os.path.join(work, n) for n in ("params.yaml", "report.yaml", "report.html"))
    row = {"name": name, "bag": bag, "dir": name, "calibration": "not run", "spec": None, "passed": False,
           "why": "", "report": None, "params": None}
    with open(os.path.join(work, "log.txt"), "w") as log:
        cmd = [hrg_report.hrg_bag_executable(), "calibrate", bag, "--out", params, "--report", report]
        for option in ("method", "params", "config"):
            if getattr(args, option):
                cmd += ["--" + option, getattr(args, option)]
        log.write("$ %s\n" % " ".join(cmd))
        log.flush()
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        log.write(p.stdout)
        if p.returncode not in (0, 1) or not os.path.isfile(report):
            lines = [line for line in p.stdout.splitlines() if line.strip() and "%" not in line]
            row["calibration"] = "failed"
            row["why"] = lines[-1] if lines else "hrg_bag calibrate exit %d" % p.returncode
            return row
        row["calibration"] = "accepted" if p.returncode == 0 else "refused"
        if p.returncode == 0:
            row["params"] = name + "/params.yaml"
        else:
            refused = [line for line in p.stdout.splitlines() if "REFUSED" in line]
            row["why"] = refused[0].strip() if refused else "refused by a quality gate"
        cmd = [sys.executable, os.path.join(HERE, "hrg_report.py"), report, "--bag", bag, "--out", html,
               "--title", "Calibration report: " + name]
        if p.returncode == 0:
            cmd += ["--params", params]
        elif args.params:
            cmd += ["--params", args.params]  # refused: the rest is processed with the prior
        if args.spec:
            cmd += ["--spec", args.spec]
        log.write("$ %s\n" % " ".join(cmd))
        log.flush()
        q = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        log.write(q.stdout)
        if q.returncode != 0:
            row["why"] = (row["why"] + "; " if row["why"] else "") + "report: " + q.stdout.strip().splitlines()[-1]
            return row
        row["report"] = name + "/report.html"
        if args.spec:
            row["spec"] = "PASS" if "spec PASS" in q.stdout else "FAIL"
            if row["spec"] == "FAIL" and not row["why"]:
                row["why"] = "out of specification (see the report)"
        row["passed"] = row["calibration"] == "accepted" and row["spec"] != "FAIL"
    return row


def main(argv):
    parser = argparse.ArgumentParser(prog="hrg_batch.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("bag_dir", help="folder of .bag files")
    parser.add_argument("out_dir", help="output folder (created)")
    parser.add_argument("--jobs", type=int, default=len(os.sched_getaffinity(0)),
                        help="bags at once (default: the cores this process may use, as nproc counts them)")
    parser.add_argument("--method", help="calibration method (hrg_bag calibrate --method)")
    parser.add_argument("--params", help="prior parameter file")
    parser.add_argument("--config", help="calibrator settings YAML")
    parser.add_argument("--spec", metavar="LIMITS.yaml", help="specification YAML for the pass/fail")
    args = parser.parse_args(argv[1:])
    if args.jobs < 1:
        sys.stderr.write("hrg_batch: --jobs must be at least 1\n")
        return 2
    if not os.path.isdir(args.bag_dir):
        sys.stderr.write("hrg_batch: %s is not a folder\n" % args.bag_dir)
        return 2
    for option in ("params", "config", "spec"):
        path = getattr(args, option)
        if path and not os.path.isfile(path):
            sys.stderr.write("hrg_batch: --%s %s: no such file\n" % (option, path))
            return 2
        if path:
            setattr(args, option, os.path.abspath(path))
    if args.spec:
        try:
            hrg_report.load_spec(args.spec)  # a bad specification is refused once, before any work
        except hrg_report.ReportError as e:
            sys.stderr.write("hrg_batch: %s\n" % e)
            return 2
    bags = sorted(os.path.abspath(os.path.join(args.bag_dir, n)) for n in os.listdir(args.bag_dir) if n.endswith(".bag"))
    if not bags:
        sys.stderr.write("hrg_batch: no .bag file in %s\n" % args.bag_dir)
        return 2
    os.makedirs(args.out_dir, exist_ok=True)
    out_dir = os.path.abspath(args.out_dir)
    rows = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(calibrate_one, bag, out_dir, args): bag for bag in bags}
        for future in concurrent.futures.as_completed(futures):
            bag = futures[future]
            try:
                row = future.result()
            except Exception as e:  # one bag's unexpected failure must not end the campaign
                name = os.path.splitext(os.path.basename(bag))[0]
                row = {"name": name, "bag": bag, "dir": name, "calibration": "failed", "spec": None,
                       "passed": False, "why": "%s: %s" % (type(e).__name__, e), "report": None, "params": None}
            rows.append(row)
            print("hrg_batch: %-24s %-9s %s %s" % (row["name"], row["calibration"],
                                                   "PASS" if row["passed"] else "FAIL", row["why"]))
    rows.sort(key=lambda r: r["name"])
    passed = sum(1 for r in rows if r["passed"])
    html = hrg_report.render("index.html.j2", rows=rows, passed=passed, total=len(rows),
                             spec=os.path.basename(args.spec) if args.spec else None,
                             bag_dir=os.path.abspath(args.bag_dir),
                             generated=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"))
    try:
        hrg_report.hrg_output_file.write_file_atomically(os.path.join(out_dir, "index.html"), html)
    except hrg_report.hrg_output_file.OutputWriteError as e:
        sys.stderr.write("hrg_batch: %s\n" % e)
        return 3
    print("hrg_batch: %d of %d passed; index in %s" % (passed, len(rows), os.path.join(out_dir, "index.html")))
    return 0 if passed == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
