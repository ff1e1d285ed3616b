#!/usr/bin/env python3
"""The figures of the documentation (docs/figures/*.png), made from a real `make run`.

  make_doc_figures.py [--run-output DIR] [--out DIR] [--hrg-bag PATH] [--rest-seconds S]

Reads what `make run` wrote in run_output/: the calibrator's report (params.report.yaml or
params.<method>.report.yaml: binned K and D and the fitted models), the session monitor's
summary.txt (the exact injected K and D harmonics) and summary.txt.yaml (the nonlinearity measured
on the verification profile before and after). For the
Allan deviation it simulates the make-run gyro at rest with `hrg_bag simulate` (the gyro of
config/scenarios/demo.yaml, its table profile replaced by one dwell) and reads `hrg_bag allan --csv`
through the calibrated parameters. Writes:

  calibration_k_d.png          K(theta) and D(theta) estimated against the theta-binned data
  nonlinearity_before_after.png  what the uncalibrated and the calibrated models leave of the
                               nonlinearity (against the binned data and the exact injected model)
  allan_deviation.png          Allan deviation of the compensated rate at rest
  north_finding_accuracy.png   the heading's sigma against window length and latitude, by the error
                               law the north-finding tests check (no run needed)

`make figures` runs it with the workspace sourced. matplotlib with the Agg backend."""
import argparse
import glob
import math
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import yaml  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_calibration  # noqa: E402  (the report plots: one reader of each tool output)
from hrg_models import YamlFileError, model, read_yaml  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DPI = 100


def fail(message):
    sys.stderr.write("make_doc_figures: %s\n" % message)
    sys.exit(1)


def load_yaml(path, what):
    if not os.path.isfile(path):
        fail("%s not found: %s (run `make run` first)" % (what, path))
    try:
        return read_yaml(path, what)
    except YamlFileError as e:
        fail(str(e))


def find_report(run_output):
    candidates = sorted(glob.glob(os.path.join(run_output, "params*.report.yaml")))
    if not candidates:
        fail("no calibration report params*.report.yaml in %s (run `make run` first)" % run_output)
    return max(candidates, key=os.path.getmtime)


def peak_deviation(values):
    """Largest |value - mean| of a curve sampled evenly over a period."""
    mean = sum(values) / len(values)
    return max(abs(v - mean) for v in values)


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print("make_doc_figures: wrote %s (%.0f kB)" % (path, os.path.getsize(path) / 1024.0))


def injected_models(summary_text_path):
    """The exact injected K and D harmonics that session_monitor prints in summary.txt (the
    'injected' column of its K(theta) and D(theta) tables), or None when the file lacks them."""
    if not os.path.isfile(summary_text_path):
        return None
    models, current = {}, None
    with open(summary_text_path) as f:
        for line in f:
            if line.startswith("K(theta)"):
                current = models.setdefault("k", {"orders": [], "cos": [], "sin": []})
            elif line.startswith("D(theta)"):
                current = models.setdefault("d", {"orders": [], "cos": [], "sin": []})
            elif current is not None and line.strip().startswith("term"):
                continue  # the table's header
            elif current is not None and line.startswith("  "):
                words = line.split()
                if words[0] == "mean" and len(words) >= 2:
                    current["mean"] = float(words[1])
                elif words[0] in ("cos", "sin") and len(words) >= 3 and words[1].endswith("th"):
                    order = int(words[1][:-2])
                    if order not in current["orders"]:
                        current["orders"].append(order)
                        current["cos"].append(0.0)
                        current["sin"].append(0.0)
                    current[words[0]][current["orders"].index(order)] = float(words[2])
            else:
                current = None
    if "mean" not in models.get("k", {}) or "mean" not in models.get("d", {}):
        return None
    return models


def binned_points(report):
    binned = report.get("binned") or {}
    theta, k, d = binned.get("theta") or [], binned.get("k") or [], binned.get("d") or []
    if not theta or len(k) != len(theta):
        fail("the report holds no binned K(theta) (method %s)" % report.get("method"))
    return theta, k, d


def figure_k_and_d(report, injected, path):
    theta, k_binned, d_binned = binned_points(report)
    k_fit = report["scale_factor"][0]
    d_fit = report["drift"][0] if report.get("drift") else None
    k0 = k_fit["mean"]
    grid = [math.pi * i / 360 for i in range(361)]
    fig, (ax_k, ax_d) = plt.subplots(1, 2, figsize=(10, 4))
    ax_k.plot(theta, [1e6 * (k / k0 - 1.0) for k in k_binned], ".", ms=3, color="0.45",
              label="binned data (%d bins)" % len(theta))
    ax_k.plot(grid, [1e6 * (model(k_fit, t) / k0 - 1.0) for t in grid], "-", color="C0",
              label="fitted K(theta), orders %s" % ",".join(str(o) for o in k_fit["orders"]))
    if injected:
        ax_k.plot(grid, [1e6 * (model(injected["k"], t) / k0 - 1.0) for t in grid], "--", color="k", lw=0.8,
                  label="injected, exact (the same orders)")
    ax_k.set_xlabel("wave angle theta (electrical rad)")
    ax_k.set_ylabel("K(theta) / K0 - 1 (ppm)")
    ax_k.set_title("scale factor, K0 = %.6f" % k0)
    if d_fit is not None:
        if any(d_binned):
            ax_d.plot(theta, [1e6 * d for d in d_binned], ".", ms=3, color="0.45", label="binned data")
        ax_d.plot(grid, [1e6 * model(d_fit, t) for t in grid], "-", color="C1",
                  label="fitted D(theta), orders %s" % ",".join(str(o) for o in d_fit["orders"]))
        if injected:
            ax_d.plot(grid, [1e6 * model(injected["d"], t) for t in grid], "--", color="k", lw=0.8,
                      label="injected, exact (the same orders)")
    ax_d.set_xlabel("wave angle theta (electrical rad)")
    ax_d.set_ylabel("D(theta) (urad/s)")
    ax_d.set_title("drift of the wave angle")
    for ax in (ax_k, ax_d):
        ax.set_xlim(0.0, math.pi)
        ax.grid(True, lw=0.3)
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo - 0.4 * (hi - lo), hi)  # room for the legend below the curves
        ax.legend(fontsize=8, loc="lower center")
    fig.suptitle("make run: dual-rate calibration at +-0.05 rad/s (%s)" %
                 ("accepted" if report.get("accepted") else "REFUSED"), fontsize=11)
    save(fig, path)


def figure_before_after(report, injected, summary, path):
    """Before: the binned K about its mean and the fitted curve (the uncalibrated model has no
    harmonics, so this is the nonlinearity it leaves). After: the calibrated model minus the exact
    injected model (what it leaves; single bins are far noisier than the fit, so they are not
    drawn). Dashed: the peaks measured on the verification profile through each processor's output
    against the truth (session_monitor's summary)."""
    theta, k_binned, _ = binned_points(report)
    k_fit = report["scale_factor"][0]
    k0 = k_fit["mean"]
    mean_binned = sum(k_binned) / len(k_binned)
    grid = [math.pi * i / 720 for i in range(721)]
    open_grid = grid[:-1]  # one period without its repeated end, for peak values
    fit_curve = [1e6 * (model(k_fit, t) / k0 - 1.0) for t in grid]
    fit_peak = max(abs(1e6 * (model(k_fit, t) / k0 - 1.0)) for t in open_grid)
    error_curve = [1e6 * (model(k_fit, t) - model(injected["k"], t)) / abs(k0) for t in grid]
    error_peak = peak_deviation([1e6 * (model(k_fit, t) - model(injected["k"], t)) / abs(k0) for t in open_grid])
    fig, (ax_b, ax_a) = plt.subplots(1, 2, figsize=(10, 4.2))
    ax_b.plot(theta, [1e6 * (k / mean_binned - 1.0) for k in k_binned], ".", ms=3, color="0.45",
              label="binned K about its mean")
    ax_b.plot(grid, fit_curve, "-", color="C3", lw=1, label="fitted K(theta) / K0 - 1 (peak %.0f ppm)" % fit_peak)
    ax_b.set_title("before calibration: the model is K0 alone")
    ax_a.plot(grid, error_curve, "-", color="C0",
              label="calibrated minus injected model (peak deviation %.2f ppm)" % error_peak)
    ax_a.set_title("after calibration: the fitted K(theta)")
    for ax, key, colour in ((ax_b, "before_ppm", "C3"), (ax_a, "after_ppm", "C2")):
        peak = summary.get(key)
        if peak is None:
            continue
        label = "verification peak, measured: %.0f ppm" % peak if key == "before_ppm" else \
            "verification peak, measured: %.2f +- %.2f ppm" % (peak, summary.get("after_sigma_ppm", 0.0))
        ax.axhline(peak, color=colour, ls="--", lw=1, label=label)
        ax.axhline(-peak, color=colour, ls="--", lw=1)
    for ax in (ax_b, ax_a):
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_xlim(0.0, math.pi)
        ax.set_xlabel("wave angle theta (electrical rad)")
        ax.set_ylabel("scale-factor error (ppm of K0)")
        ax.grid(True, lw=0.3)
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo - 0.35 * (hi - lo), hi)  # room for the legend below the curves
        ax.legend(fontsize=7.5, loc="lower center")
    fig.suptitle("make run: scale-factor nonlinearity before and after the dual-rate calibration", fontsize=11)
    save(fig, path)


def rest_scenario(seconds, directory):
    """The make-run gyro (config/scenarios/demo.yaml) on a table at rest for `seconds`."""
    scenario = load_yaml(os.path.join(ROOT, "config", "scenarios", "demo.yaml"), "scenario")
    scenario["turntable"]["profile"] = [{"type": "dwell", "duration": float(seconds), "label": "rest"}]
    path = os.path.join(directory, "rest.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(scenario, f)
    return path


def run(command):
    print("make_doc_figures: " + " ".join(command))
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if done.returncode != 0:
        fail("%s failed (exit %d): %s" % (command[0], done.returncode, done.stderr.strip()[-500:]))
    return done.stdout


def figure_allan(hrg_bag, params, seconds, path):
    with tempfile.TemporaryDirectory() as tmp:
        bag, csv = os.path.join(tmp, "rest.bag"), os.path.join(tmp, "allan.csv")
        run([hrg_bag, "simulate", "--scenario", rest_scenario(seconds, tmp), "--out", bag])
        readings = run([hrg_bag, "allan", bag, "--params", params, "--csv", csv])
        taus, devs, errs = plot_calibration.read_allan_csv(csv)
    to_deg_h = 180.0 / math.pi * 3600.0
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.loglog(taus, [d * to_deg_h for d in devs], "o-", ms=3, color="C0", label="overlapping Allan deviation")
    ax.fill_between(taus, [max(d - e, 1e-12) * to_deg_h for d, e in zip(devs, errs)],
                    [(d + e) * to_deg_h for d, e in zip(devs, errs)], color="C0", alpha=0.25, label="1 sigma")
    # The tool's slope readings (IEEE 952), as printed by hrg_bag allan.
    lines = [l.strip() for l in readings.splitlines()[1:] if l.strip()]
    ax.text(0.02, 0.03, "\n".join(lines), transform=ax.transAxes, fontsize=7, family="monospace",
            va="bottom", bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    ax.set_xlabel("averaging time tau (s)")
    ax.set_ylabel("Allan deviation of the rate (deg/h)")
    ax.set_title("compensated rate at rest, %.0f s (make-run gyro, calibrated model)" % seconds, fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8, loc="upper right")
    save(fig, path)


# North finding: the error law the core's tests check (src/core/integration/north_finding_accuracy_test.cpp),
# with the shipped gyro's white angle noise seen in the body (4.9e-6 rad per sample at 200 Hz, K0 0.56).
EARTH_RATE = 7.292115e-5  # rad/s
NORTH_NOISE = 4.9e-6 / 0.56  # rad of body angle per sample
NORTH_RATE_HZ = 200.0


def north_noise_rate(seconds):
    """rad/s, 1 sigma: a rate fitted on the integrated angle over `seconds` of white angle noise."""
    return math.sqrt(12.0 * NORTH_NOISE ** 2 / (NORTH_RATE_HZ * seconds ** 3))


def north_heading_sigma(seconds, latitude, bias=0.0, level=0.0, positions=1):
    """rad: the heading's sigma. positions=1: static (the bias a floor); 2: two positions 180 deg apart
    of seconds/2 each (the bias cancels; the rate difference of two half windows: twice the noise)."""
    h = EARTH_RATE * math.cos(latitude)
    noise = north_noise_rate(seconds) * (2.0 if positions == 2 else 1.0)
    floor = bias if positions == 1 else 0.0
    return math.sqrt((noise ** 2 + floor ** 2) / h ** 2 + (level * math.tan(latitude)) ** 2)


def figure_north_finding(path):
    windows = [10.0 * 1.1 ** k for k in range(60) if 10.0 * 1.1 ** k <= 1200.0]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for bias, style in ((1e-8, "-"), (3e-9, "--")):
        ax1.loglog(windows, [1e3 * north_heading_sigma(t, 0.9, bias) for t in windows], "C0" + style,
                   label="static triad, residual bias %.0e rad/s" % bias)
    ax1.loglog(windows, [1e3 * north_heading_sigma(t, 0.9, positions=2) for t in windows], "C1-",
               label="indexed, two positions of T/2 (bias cancels)")
    ax1.loglog(windows, [1e3 * north_noise_rate(t) / (EARTH_RATE * math.cos(0.9)) for t in windows], "k:",
               label="white angle noise alone, T^-3/2")
    ax1.set_xlabel("window length T (s)")
    ax1.set_ylabel("heading sigma (mrad)")
    ax1.set_title("latitude 0.9 rad (51.6 deg), exact level")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=8)
    latitudes = [math.radians(d) for d in range(0, 81)]
    for seconds, bias, positions, colour, label in (
        (120.0, 1e-8, 1, "C0", "static 120 s, bias 1e-8 rad/s"),
        (120.0, 0.0, 2, "C1", "indexed 2 x 60 s"),
        (600.0, 0.0, 2, "C2", "indexed 2 x 300 s"),
    ):
        ax2.semilogy([math.degrees(x) for x in latitudes],
                     [1e3 * north_heading_sigma(seconds, x, bias, 0.0, positions) for x in latitudes],
                     colour + "-", label=label)
        ax2.semilogy([math.degrees(x) for x in latitudes],
                     [1e3 * north_heading_sigma(seconds, x, bias, 1e-4, positions) for x in latitudes],
                     colour + "--", label=label + ", level 0.1 mrad")
    ax2.axvline(80.0, color="grey", lw=0.8)
    ax2.text(79.0, ax2.get_ylim()[1] * 0.5, "refused above max_latitude", rotation=90, ha="right", va="top",
             fontsize=8)
    ax2.set_xlabel("latitude (deg)")
    ax2.set_ylabel("heading sigma (mrad)")
    ax2.set_title("against latitude")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--run-output", default=os.path.join(ROOT, "run_output"))
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "figures"))
    parser.add_argument("--hrg-bag", default=None, help="the hrg_bag executable (default: from the workspace)")
    parser.add_argument("--rest-seconds", type=float, default=1800.0, help="length of the simulated rest")
    args = parser.parse_args(argv)
    if args.rest_seconds < 100.0:
        fail("--rest-seconds must be at least 100 (got %g)" % args.rest_seconds)
    hrg_bag = args.hrg_bag or os.path.join(ROOT, ".ws", "devel", "lib", "hrg_gyro", "hrg_bag")
    if not os.access(hrg_bag, os.X_OK):
        fail("--hrg-bag: %s is not an executable (build first: make build)" % hrg_bag)
    report = load_yaml(find_report(args.run_output), "calibration report")
    if not report.get("scale_factor"):
        fail("the calibration report holds no K(theta) estimate (%s)" % report.get("reason"))
    summary_path = os.path.join(args.run_output, "summary.txt.yaml")
    summary = load_yaml(summary_path, "session summary")
    params = os.path.join(args.run_output, "params.yaml")
    if not os.path.isfile(params):
        fail("calibrated parameters not found: %s" % params)
    os.makedirs(args.out, exist_ok=True)
    injected = injected_models(os.path.join(args.run_output, "summary.txt"))
    figure_k_and_d(report, injected, os.path.join(args.out, "calibration_k_d.png"))
    if injected is None:
        fail("no injected K(theta) table in %s" % os.path.join(args.run_output, "summary.txt"))
    figure_before_after(report, injected, summary, os.path.join(args.out, "nonlinearity_before_after.png"))
    figure_allan(hrg_bag, params, args.rest_seconds, os.path.join(args.out, "allan_deviation.png"))
    figure_north_finding(os.path.join(args.out, "north_finding_accuracy.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
