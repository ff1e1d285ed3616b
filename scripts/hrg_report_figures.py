"""The figures of the HTML calibration report (hrg_report.py) and what they are drawn from: the
session's table profile and temperature read from its bag, the Allan deviation of the compensated rate
at rest (by `hrg_bag allan`) with its noise terms, K(theta) and D(theta) against the binned data.
Each figure is a PNG embedded as a data URI. A module beside the scripts."""
import base64
import csv
import io
import math
import os
import shutil
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from hrg_models import model, model_std, one_line  # noqa: E402
from hrg_report_validation import (RAD_S_SQRT_S_TO_DEG_H_SQRT_H, RAD_S_TO_DEG_H,  # noqa: E402
                                   RAD_SQRT_S_TO_DEG_SQRT_H, ReportError, load_yaml)

MIN_CLUSTERS = 9  # Allan points with fewer independent clusters are drawn, not read (as the core does)


def fmt(value, digits=6):
    """The one number format of the page (the test compares the page with the YAML through it)."""
    return "%.*g" % (digits, value)


def figure_uri(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


# ---------------------------------------------------------------------------------------------
# The session, from the bag.

def read_session(bag_path, stride=10):
    """Turntable (t, rate) and channel temperature (t, degC) every `stride`-th message of the bag."""
    import rosbag  # only needed with --bag
    try:
        bag = rosbag.Bag(bag_path)
    except Exception as e:  # rosbag raises several unrelated types for unreadable files
        raise ReportError("cannot open --bag %s: %s" % (bag_path, e))
    topics = bag.get_type_and_topic_info().topics
    by_type = {}
    for name, info in topics.items():
        by_type.setdefault(info.msg_type, []).append(name)
    table_topics = by_type.get("hrg_gyro/TurntableState", [])
    channel_topics = by_type.get("hrg_gyro/ChannelAmplitudes", [])
    if len(channel_topics) != 1:
        raise ReportError("--bag %s: needs exactly one hrg_gyro/ChannelAmplitudes topic, has %d" %
                          (bag_path, len(channel_topics)))
    session = {"table_t": [], "table_rate": [], "temp_t": [], "temperature": [], "table_topic": None,
               "channels_topic": channel_topics[0], "channels_t0": None, "channels_t1": None}
    if len(table_topics) == 1:
        session["table_topic"] = table_topics[0]
    counts = {}
    for topic, raw, _ in bag.read_messages(topics=[t for t in (session["table_topic"], channel_topics[0]) if t],
                                           raw=True):
        counts[topic] = counts.get(topic, 0) + 1
        if topic == channel_topics[0]:
            if counts[topic] == 1 or counts[topic] % stride == 0:
                msg = raw[4]()
                msg.deserialize(raw[1])
                t = msg.header.stamp.to_sec()
                if session["channels_t0"] is None:
                    session["channels_t0"] = t
                session["channels_t1"] = t
                if math.isfinite(msg.temperature):
                    session["temp_t"].append(t)
                    session["temperature"].append(msg.temperature)
        elif counts[topic] % stride == 0 or counts[topic] == 1:
            msg = raw[4]()
            msg.deserialize(raw[1])
            session["table_t"].append(msg.header.stamp.to_sec())
            session["table_rate"].append(msg.rate)
    bag.close()
    if session["channels_t0"] is None:
        raise ReportError("--bag %s: the channels topic is empty" % bag_path)
    return session


def longest_rest(times, rates, tolerance, trim=1.0):
    """(from, to) of the longest stretch with |table rate| <= tolerance, `trim` s cut at each end."""
    best, start = None, None
    for i, (t, r) in enumerate(zip(times, rates)):
        still = abs(r) <= tolerance
        if still and start is None:
            start = t
        if (not still or i == len(times) - 1) and start is not None:
            end = t if still else times[i - 1]
            if best is None or end - start > best[1] - best[0]:
                best = (start, end)
            start = None
    if best is None or best[1] - best[0] <= 2 * trim + 1.0:
        return None
    return best[0] + trim, best[1] - trim


def hrg_bag_executable():
    """hrg_bag beside this script (install space), else catkin's libexec lookup, else PATH."""
    beside = os.path.join(os.path.dirname(os.path.abspath(__file__)), "hrg_bag")
    if os.access(beside, os.X_OK):
        return beside
    if os.environ.get("HRG_BAG"):
        return os.environ["HRG_BAG"]
    try:
        found = subprocess.run(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, universal_newlines=True)
        if found.returncode == 0 and found.stdout.strip():
            return found.stdout.strip()
    except OSError:
        pass
    on_path = shutil.which("hrg_bag")
    if on_path:
        return on_path
    raise ReportError("hrg_bag not found (beside this script, through catkin_find or on PATH)")


def run_allan(bag_path, params_path, window, work):
    """The Allan deviation of the compensated rate over `window`, by `hrg_bag allan`."""
    out_csv, out_yaml = os.path.join(work, "allan.csv"), os.path.join(work, "allan.yaml")
    cmd = [hrg_bag_executable(), "allan", bag_path, "--csv", out_csv, "--yaml", out_yaml,
           "--from", repr(window[0]), "--to", repr(window[1])]
    if params_path:
        cmd += ["--params", params_path]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if p.returncode != 0:
        last = (p.stderr.strip().splitlines() or ["exit %d" % p.returncode])[-1]
        raise ReportError("hrg_bag allan failed on %s: %s" % (bag_path, one_line(last)))
    curve = []
    try:
        with open(out_csv) as f:
            for row in csv.DictReader(f):
                curve.append({k: float(v) for k, v in row.items()})
    except (OSError, ValueError, TypeError) as e:
        raise ReportError("cannot read the Allan deviation hrg_bag allan wrote: %s" % one_line(e))
    readings = load_yaml(out_yaml, "Allan readings")
    return curve, readings


def allan_terms(curve, readings):
    """The IEEE 952 readings with, for a term the record does not show, the upper bound the curve
    still gives: each noise term's own line lies at or below the measured curve."""
    usable = [p for p in curve if p["clusters"] >= MIN_CLUSTERS]
    longest = usable[-1]["tau"] if usable else 0.0

    def bound(name, value_at):
        if not usable:
            return None
        return min((value_at(p), p["tau"]) for p in usable)

    terms = []
    specs = [
        ("angle_random_walk", "angle random walk N", "slope -1/2 line read at tau = 1 s",
         "rad/sqrt(s)", "deg/sqrt(h)", RAD_SQRT_S_TO_DEG_SQRT_H,
         lambda p: p["deviation"] * math.sqrt(p["tau"])),
        ("bias_instability", "bias instability B", "flat minimum / 0.664", "rad/s", "deg/h", RAD_S_TO_DEG_H,
         lambda p: p["deviation"] / 0.664),
        ("rate_random_walk", "rate random walk K", "slope +1/2 line read at tau = 3 s",
         "rad/s/sqrt(s)", "deg/h/sqrt(h)", RAD_S_SQRT_S_TO_DEG_H_SQRT_H,
         lambda p: p["deviation"] * math.sqrt(3.0 / p["tau"])),
        ("angle_white_noise", "angle white noise Q", "slope -1 line: sigma = sqrt(3) Q / tau",
         "rad", "arcsec", 180.0 / math.pi * 3600.0, lambda p: p["deviation"] * p["tau"] / math.sqrt(3.0)),
    ]
    for key, label, how, unit, alt_unit, alt_scale, value_at in specs:
        r = readings.get(key) or {}
        term = {"key": key, "label": label, "how": how, "unit": unit, "alt_unit": alt_unit, "alt_scale": alt_scale,
                "identified": bool(r.get("identified")), "value": None, "bound": None, "note": ""}
        if term["identified"]:
            term["value"] = r["value"]
            term["note"] = "read from tau %s..%s s" % (fmt(r["tau_min"], 3), fmt(r["tau_max"], 3))
        else:
            b = bound(key, value_at)
            if b is not None:
                term["bound"] = b[0]
                term["note"] = ("not observable in this record (%s s at rest, tau read up to %s s): no stretch of "
                                "the curve has that slope over a factor of 3 in tau; the curve at tau = %s s bounds "
                                "it from above" % (fmt(readings.get("record_length", 0.0), 4), fmt(longest, 3),
                                                   fmt(b[1], 3)))
            else:
                term["note"] = "not observable: the record is too short"
        terms.append(term)
    return terms


# ---------------------------------------------------------------------------------------------
# Figures.

def profile_figure(session, window):
    t0 = session["channels_t0"]
    fig, ax = plt.subplots(figsize=(7.2, 2.6))
    if session["table_t"]:
        ax.plot([t - t0 for t in session["table_t"]], session["table_rate"], "-", lw=0.8)
    if window:
        ax.axvspan(window[0] - t0, window[1] - t0, color="tab:green", alpha=0.25, label="rest used for the Allan deviation")
        ax.legend(fontsize=8, loc="upper right")
    ax.set_xlabel("time from the first channel sample (s)")
    ax.set_ylabel("table rate (rad/s)")
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    return figure_uri(fig)


def temperature_figure(session):
    t0 = session["channels_t0"]
    fig, ax = plt.subplots(figsize=(7.2, 2.2))
    ax.plot([t - t0 for t in session["temp_t"]], session["temperature"], "-", lw=0.8, color="tab:red")
    ax.set_xlabel("time from the first channel sample (s)")
    ax.set_ylabel("temperature (degC)")
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    return figure_uri(fig)


def model_figure(theta, binned, estimate, k0, scale, ylabel, band_sigma):
    """Binned data, fit and its band; values are (x / k0 - 1) * 1e6 for K, x * scale otherwise."""
    grid = [math.pi * i / 360 for i in range(361)]
    if k0 is not None:
        tr = lambda v: 1e6 * (v / k0 - 1.0)  # noqa: E731
        tr_std = lambda s: 1e6 * s / abs(k0)  # noqa: E731
    else:
        tr = lambda v: v * scale  # noqa: E731
        tr_std = lambda s: s * scale  # noqa: E731
    fit = [tr(model(estimate, t)) for t in grid]
    half = [band_sigma * tr_std(model_std(estimate, t)) for t in grid]
    fig, (ax, ax_band) = plt.subplots(2, 1, figsize=(7.2, 3.8), sharex=True, gridspec_kw={"height_ratios": [3, 1.2]})
    if theta and binned:
        ax.plot(theta, [tr(v) for v in binned], ".", ms=3, color="tab:gray", label="binned data")
    ax.fill_between(grid, [f - h for f, h in zip(fit, half)], [f + h for f, h in zip(fit, half)], color="tab:blue",
                    alpha=0.3, label="95 % confidence band of the fit")
    ax.plot(grid, fit, "-", lw=1.0, color="tab:blue", label="fitted model")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8)
    # The band is often far narrower than the curve's swing: its half-width on its own scale.
    ax_band.plot(grid, half, "-", lw=1.0, color="tab:blue")
    ax_band.set_ylim(0.0, 1.15 * max(half))
    ax_band.set_ylabel("band half-width", fontsize=8)
    ax_band.set_xlabel("theta (electrical rad)")
    ax_band.grid(True, lw=0.3)
    fig.tight_layout()
    return figure_uri(fig)


def allan_figure(curve, terms):
    fig, ax = plt.subplots(figsize=(7.2, 3.6))
    taus = [p["tau"] for p in curve]
    devs = [p["deviation"] * RAD_S_TO_DEG_H for p in curve]
    errs = [p["error"] * RAD_S_TO_DEG_H for p in curve]
    ax.loglog(taus, devs, "o-", ms=3, label="overlapping Allan deviation")
    ax.fill_between(taus, [max(d - e, 1e-30) for d, e in zip(devs, errs)], [d + e for d, e in zip(devs, errs)],
                    alpha=0.3, label="1 sigma")
    lines = {"angle_random_walk": (lambda v, t: v / math.sqrt(t), "N / sqrt(tau)"),
             "rate_random_walk": (lambda v, t: v * math.sqrt(t / 3.0), "K sqrt(tau / 3)"),
             "bias_instability": (lambda v, t: 0.664 * v, "0.664 B")}
    for term in terms:
        if term["identified"] and term["key"] in lines:
            f, label = lines[term["key"]]
            ax.loglog(taus, [f(term["value"], t) * RAD_S_TO_DEG_H for t in taus], "--", lw=0.8, label=label)
    ax.set_xlabel("tau (s)")
    ax.set_ylabel("Allan deviation (deg/h)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return figure_uri(fig)


def triad_axis_figures(report, name, band_sigma):
    """One axis of a triad: its K(theta) figure and summary, from its own report."""
    r = report["axis_reports"][name]
    k_est = (r.get("scale_factor") or [None])[0]
    binned = r.get("binned") or {}
    axis = {"name": name, "r": r, "k_figure": None, "after_rms": None}
    if k_est:
        axis["k_figure"] = model_figure(binned.get("theta") or [], binned.get("k"), k_est, k_est["mean"], None,
                                        "K / K0 - 1 (ppm)", band_sigma)
        axis["after_rms"] = 1e6 * k_est["residual_rms"] / abs(k_est["mean"])
    return axis
