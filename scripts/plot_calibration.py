#!/usr/bin/env python3
"""Plots for test engineers (matplotlib, PNG).

  plot_calibration.py calibration REPORT.yaml OUT.png
      binned K(theta) and D(theta) with the fitted models, the residual of K after compensation
      (binned data minus the model, in ppm of K0), and the theta coverage of each plateau group.
      A frequency-dependent (thermal) result is drawn at the middle frequency of its nodes, where
      the calibrator moved its binned data; the residual panel adds the model at each node minus
      the model there (the temperature dependence, on the residual's scale).
  plot_calibration.py allan ALLAN.csv OUT.png
      the Allan deviation of the compensated rate (hrg_bag allan --csv), with its 1-sigma band.

The report is the YAML the calibrator and `hrg_bag calibrate --report` write."""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The module beside this script (its own folder first, as hrg_report.py does).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hrg_models import YamlFileError, at_frequency, model, parse_yaml, read_yaml  # noqa: E402


def plot_calibration(report_path, out_path):
    try:
        r = read_yaml(report_path, "calibration report")
    except YamlFileError as e:
        raise SystemExit(str(e))
    binned = r.get("binned") or {}
    theta = binned.get("theta") or []
    if not r.get("scale_factor"):
        raise SystemExit("the report has no K(theta) estimate (method %s, %s)" % (r.get("method"), r.get("reason")))
    k_est = r["scale_factor"][0]
    d_est = r["drift"][0] if r.get("drift") else None
    nodes = r.get("frequency_nodes") or []
    node_models, where = [], ""
    if len(nodes) > 1 and len(r["scale_factor"]) == len(nodes):
        written = parse_yaml(r["parameters"]) if r.get("accepted") else None
        natural = not written or written["scale_factor"].get("interpolation") != "piecewise_linear"
        f_mid = 0.5 * (nodes[0] + nodes[-1])
        node_models = list(zip(nodes, r["scale_factor"]))
        k_est = at_frequency(r["scale_factor"], nodes, f_mid, natural)
        if r.get("drift"):
            d_est = at_frequency(r["drift"], nodes, f_mid, natural)
        where = " at %.3f Hz" % f_mid
    k0 = k_est["mean"]
    grid = [math.pi * i / 720 for i in range(721)]
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    status = "accepted" if r.get("accepted") else "REFUSED: " + str(r.get("reason"))
    fig.suptitle("hrg_gyro calibration, method %s (%s)" % (r.get("method"), status))

    ax = axes[0][0]
    ax.plot(theta, [1e6 * (k / k0 - 1.0) for k in binned.get("k", [])], ".", ms=3, label="binned data")
    ax.plot(grid, [1e6 * (model(k_est, t) / k0 - 1.0) for t in grid], "-", label="fitted model" + where)
    ax.set_xlabel("theta (electrical rad)")
    ax.set_ylabel("K / K0 - 1 (ppm)")
    ax.set_title("scale factor%s, K0 = %.9f, peak %.1f ppm" % (where, k0, r.get("nonlinearity_ppm", 0.0)))
    ax.legend()

    ax = axes[0][1]
    if d_est is not None and any(binned.get("d", [])):
        ax.plot(theta, [1e6 * d for d in binned["d"]], ".", ms=3, label="binned data")
    if d_est is not None:
        ax.plot(grid, [1e6 * model(d_est, t) for t in grid], "-", label="fitted model")
    ax.set_xlabel("theta (electrical rad)")
    ax.set_ylabel("D (urad/s)")
    ax.set_title("drift")
    ax.legend()

    ax = axes[1][0]
    if theta:
        residual = [1e6 * (k - model(k_est, t)) / abs(k0) for t, k in zip(theta, binned.get("k", []))]
        ax.plot(theta, residual, ".", ms=3)
        rms = math.sqrt(sum(x * x for x in residual) / len(residual))
        ax.set_title("residual of binned K after compensation (rms %.2f ppm; bins are noisier than the fit)" % rms)
    for f, fit in node_models:
        ax.plot(grid, [1e6 * (model(fit, t) - model(k_est, t)) / abs(k0) for t in grid], "--", lw=0.8,
                label="K(%.3f Hz) - K%s" % (f, where))
    if node_models:
        ax.legend(fontsize=8)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("theta (electrical rad)")
    ax.set_ylabel("(K_binned - K_model) / |K0| (ppm)")

    ax = axes[1][1]
    plateaus = r.get("plateaus") or []
    if plateaus:
        labels = ["%+.4f rad/s" % p["rate"] for p in plateaus]
        ax.bar(labels, [100.0 * p["coverage"] for p in plateaus])
        for i, p in enumerate(plateaus):
            ax.text(i, 100.0 * p["coverage"] + 1, "%.1f s, %.1f half-turns" % (p["duration"], p["turns"]),
                    ha="center", fontsize=8)
        ax.set_ylim(0, 115)
    ax.set_ylabel("theta coverage (%)")
    ax.set_title("coverage per plateau group (overall %.1f %%)" % (100.0 * r.get("coverage", 0.0)))
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)


def read_allan_csv(csv_path):
    """(taus, deviations, errors) of an `hrg_bag allan --csv` file; SystemExit on another file."""
    taus, devs, errs = [], [], []
    with open(csv_path) as f:
        header = f.readline().strip().split(",")
        if header[:3] != ["tau", "deviation", "error"]:
            raise SystemExit("%s is not an hrg_bag allan CSV" % csv_path)
        for line in f:
            tau, dev, err = (float(x) for x in line.split(",")[:3])
            taus.append(tau)
            devs.append(dev)
            errs.append(err)
    return taus, devs, errs


def plot_allan(csv_path, out_path):
    taus, devs, errs = read_allan_csv(csv_path)
    to_deg_h = 180.0 / math.pi * 3600.0
    fig, ax = plt.subplots(figsize=(8, 6))
    ax.loglog(taus, [d * to_deg_h for d in devs], "o-", ms=3, label="overlapping Allan deviation")
    ax.fill_between(taus, [(d - e) * to_deg_h for d, e in zip(devs, errs)],
                    [(d + e) * to_deg_h for d, e in zip(devs, errs)], alpha=0.3, label="1 sigma")
    ax.set_xlabel("tau (s)")
    ax.set_ylabel("Allan deviation (deg/h)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    ax.set_title("compensated rate")
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)


def main(argv):
    if len(argv) != 4 or argv[1] not in ("calibration", "allan"):
        sys.stderr.write(__doc__)
        return 2
    (plot_calibration if argv[1] == "calibration" else plot_allan)(argv[2], argv[3])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
