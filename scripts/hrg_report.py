#!/usr/bin/env python3
"""One calibration as a self-contained HTML report a test engineer can sign.

  hrg_report.py REPORT.yaml --out OUT.html [--bag BAG] [--params CALIBRATED.yaml] [--spec LIMITS.yaml]
                [--verification SUMMARY.yaml] [--rest FROM TO] [--title TEXT]

REPORT.yaml is the calibration report (`hrg_bag calibrate --report`, or the calibrator node's
<parameter file>.<method>.report.yaml). With --bag, the session's turntable profile and temperature
are drawn from the bag, and the Allan deviation of the compensated rate is computed over the bag's
longest rest (or --rest FROM TO, channel stamps in s) by `hrg_bag allan`, which runs the package's
processor with the calibrated parameters (--params, else the parameters in the report, else the
nominal model). --verification adds the before/after nonlinearity measured on a verification
profile against ground truth (session_monitor's summary YAML, as `make run` writes it). --spec
checks the figures against the gyro's specification (see SPEC_KEYS).

Everything the page shows is embedded (PNG figures as data URIs, styles inline): it opens offline
and prints on A4. Exit 0 the report was written (whatever the pass/fail), 2 bad usage or input,
3 the report could not be written.
"""
import argparse
import base64
import csv
import datetime
import io
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import yaml  # noqa: E402

RAD_S_TO_DEG_H = 180.0 / math.pi * 3600.0
RAD_SQRT_S_TO_DEG_SQRT_H = 180.0 / math.pi * 60.0  # rad/sqrt(s) -> deg/sqrt(h)
RAD_S_SQRT_S_TO_DEG_H_SQRT_H = RAD_S_TO_DEG_H * 60.0  # rad/s/sqrt(s) -> deg/h/sqrt(h)

# The specification keys: each names its quantity and its unit; the value is the largest allowed.
# (quantity compared, factor from the SI value the report computes to the key's unit)
SPEC_KEYS = {
    "max_nonlinearity_ppm": ("nonlinearity", 1.0),
    "max_harmonic_std_ppm": ("harmonic_std", 1.0),
    "max_arw_rad_per_sqrt_s": ("angle_random_walk", 1.0),
    "max_arw_deg_per_sqrt_h": ("angle_random_walk", RAD_SQRT_S_TO_DEG_SQRT_H),
    "max_bias_instability_rad_per_s": ("bias_instability", 1.0),
    "max_bias_instability_deg_per_h": ("bias_instability", RAD_S_TO_DEG_H),
    "max_rrw_rad_per_s_per_sqrt_s": ("rate_random_walk", 1.0),
    "max_rrw_deg_per_h_per_sqrt_h": ("rate_random_walk", RAD_S_SQRT_S_TO_DEG_H_SQRT_H),
}
SPEC_OTHER_KEYS = {"name", "require_accepted"}

MIN_CLUSTERS = 9  # Allan points with fewer independent clusters are drawn, not read (as the core does)


class Loader(yaml.SafeLoader):
    """YAML 1.2 numbers: yaml-cpp writes 1e-05, which PyYAML's YAML 1.1 rules would read as a string."""


Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                    |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                    |\.[0-9_]+(?:[eE][-+][0-9]+)?
                    |[-+]?\.(?:inf|Inf|INF)
                    |\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."))


class ReportError(Exception):
    """Bad usage or input: message printed, exit 2."""


def fmt(value, digits=6):
    """The one number format of the page (the test compares the page with the YAML through it)."""
    return "%.*g" % (digits, value)


def model(estimate, theta):
    value = estimate["mean"]
    for k, a, b in zip(estimate["orders"], estimate["cos"], estimate["sin"]):
        value += a * math.cos(k * theta) + b * math.sin(k * theta)
    return value


def model_std(estimate, theta):
    """1-sigma of the model at theta from the coefficients' standard errors, taken as independent."""
    var = estimate["mean_std"] ** 2
    for k, sa, sb in zip(estimate["orders"], estimate["cos_std"], estimate["sin_std"]):
        var += (sa * math.cos(k * theta)) ** 2 + (sb * math.sin(k * theta)) ** 2
    return math.sqrt(var)


def figure_uri(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def load_yaml(path, what):
    try:
        with open(path) as f:
            data = yaml.load(f, Loader=Loader)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as e:
        raise ReportError("cannot read %s %s: %s" % (what, path, e))
    if not isinstance(data, dict):
        raise ReportError("%s %s is not a YAML map" % (what, path))
    return data


def load_spec(path):
    spec = load_yaml(path, "--spec")
    for key, value in spec.items():
        if key not in SPEC_KEYS and key not in SPEC_OTHER_KEYS:
            raise ReportError("--spec %s: unknown key '%s' (known: %s)" %
                              (path, key, ", ".join(sorted(list(SPEC_KEYS) + list(SPEC_OTHER_KEYS)))))
        if key in SPEC_KEYS and (isinstance(value, bool) or not isinstance(value, (int, float)) or
                                 not math.isfinite(value) or value <= 0):
            raise ReportError("--spec %s: '%s' must be a positive number, not %r" % (path, key, value))
        if key == "require_accepted" and not isinstance(value, bool):
            raise ReportError("--spec %s: 'require_accepted' must be true or false, not %r" % (path, value))
    return spec


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
        raise ReportError("hrg_bag allan failed on %s: %s" % (bag_path, p.stderr.strip().splitlines()[-1:]))
    curve = []
    with open(out_csv) as f:
        for row in csv.DictReader(f):
            curve.append({k: float(v) for k, v in row.items()})
    with open(out_yaml) as f:
        readings = yaml.load(f, Loader=Loader)
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


# ---------------------------------------------------------------------------------------------

def harmonic_rows(estimate, k0=None):
    rows = [{"term": "mean", "order": 0, "cos": estimate["mean"], "cos_std": estimate["mean_std"], "sin": None,
             "sin_std": None, "ppm": None}]
    for k, a, sa, b, sb in zip(estimate["orders"], estimate["cos"], estimate["cos_std"], estimate["sin"],
                               estimate["sin_std"]):
        rows.append({"term": "order %d" % k, "order": k, "cos": a, "cos_std": sa, "sin": b, "sin_std": sb,
                     "ppm": 1e6 * math.hypot(a, b) / abs(k0) if k0 else None})
    return rows


def find_template_dir():
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.path.join(here, "..", "templates"),                       # source tree
                  os.path.join(here, "..", "..", "share", "hrg_gyro", "templates")]  # install space
    try:
        import rospkg
        candidates.append(os.path.join(rospkg.RosPack().get_path("hrg_gyro"), "templates"))
    except Exception:  # no ROS environment: the candidates above
        pass
    for c in candidates:
        if os.path.isfile(os.path.join(c, "report.html.j2")):
            return os.path.normpath(c)
    raise ReportError("the report template report.html.j2 was not found (looked in %s)" % ", ".join(candidates))


def render(template_name, **context):
    import jinja2
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(find_template_dir()), autoescape=True,
                             undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.filters["num"] = fmt
    return env.get_template(template_name).render(**context)


def write_atomically(path, text):
    directory = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=directory)
        with os.fdopen(fd, "w") as f:
            f.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 would hide the report from the others
        os.replace(tmp, path)
    except OSError as e:
        raise OSError("report %s not written: %s" % (path, e))


def build(args):
    report = load_yaml(args.report, "calibration report")
    for key in ("method", "accepted"):
        if key not in report:
            raise ReportError("%s is not a calibration report: no '%s' key" % (args.report, key))
    spec = load_spec(args.spec) if args.spec else None
    verification = load_yaml(args.verification, "--verification") if args.verification else None
    if verification is not None:
        for key in ("before_ppm", "after_ppm"):
            if key not in verification:
                raise ReportError("--verification %s: no '%s' key (session_monitor's summary YAML)" %
                                  (args.verification, key))
    if args.rest and not args.rest[0] < args.rest[1]:
        raise ReportError("--rest FROM TO: FROM must be before TO")
    if not args.rest_max_rate >= 0.0 or not math.isfinite(args.rest_max_rate):
        raise ReportError("--rest-max-rate must be a finite number >= 0, not %r" % args.rest_max_rate)

    k_est = (report.get("scale_factor") or [None])[0]
    d_est = (report.get("drift") or [None])[0]
    frequency_note = ""
    if len(report.get("scale_factor") or []) > 1:
        frequency_note = ("a frequency-dependent result: the figures and tables show its first node (%s Hz)" %
                          fmt((report.get("frequency_nodes") or [float("nan")])[0]))
    binned = report.get("binned") or {}
    theta = binned.get("theta") or []
    band_sigma = 1.96
    ctx = {"title": args.title or "Calibration report: " + os.path.basename(args.bag or args.report),
           "generated": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "report_path": os.path.basename(args.report), "bag_path": os.path.basename(args.bag) if args.bag else None,
           "r": report, "frequency_note": frequency_note, "band_sigma": band_sigma,
           "k_rows": harmonic_rows(k_est, k_est["mean"]) if k_est else [],
           "d_rows": harmonic_rows(d_est) if d_est else [],
           "k_figure": None, "d_figure": None, "nonlinearity": None, "verification": verification,
           "session": None, "profile_figure": None, "temperature_figure": None, "rest": None,
           "allan": None, "allan_figure": None, "allan_terms": [], "spec": None, "spec_rows": [], "overall": None}

    if k_est:
        k0 = k_est["mean"]
        ctx["k_figure"] = model_figure(theta, binned.get("k"), k_est, k0, None, "K / K0 - 1 (ppm)", band_sigma)
        # The calibrator's own residual: the binned K about the fit seen through the same bins and
        # smoothing window as the data (the bins alone are smoothed by the window; the drawn fit is not).
        ctx["nonlinearity"] = {"before": report.get("nonlinearity_ppm"),
                               "after_rms": 1e6 * k_est["residual_rms"] / abs(k0)}
    if d_est:
        ctx["d_figure"] = model_figure(theta, binned.get("d"), d_est, None, 1e6, "D (urad/s)", band_sigma)

    params_path, work = args.params, tempfile.mkdtemp(prefix="hrg_report.")
    try:
        if args.bag:
            session = read_session(args.bag)
            if args.rest:
                window = tuple(args.rest)
            elif session["table_topic"]:
                window = longest_rest(session["table_t"], session["table_rate"], args.rest_max_rate)
            else:  # a static recording without a table: all of it is at rest
                window = (session["channels_t0"], session["channels_t1"])
            ctx["session"] = {"duration": session["channels_t1"] - session["channels_t0"],
                              "has_table": bool(session["table_t"]), "has_temperature": bool(session["temperature"])}
            if session["temperature"]:
                ctx["session"]["temp_min"] = min(session["temperature"])
                ctx["session"]["temp_max"] = max(session["temperature"])
                ctx["temperature_figure"] = temperature_figure(session)
            ctx["profile_figure"] = profile_figure(session, window)
            if window:
                if not params_path and report.get("accepted") and report.get("parameters"):
                    params_path = os.path.join(work, "parameters.yaml")
                    with open(params_path, "w") as f:
                        f.write(report["parameters"])
                curve, readings = run_allan(args.bag, params_path, window, work)
                ctx["rest"] = {"from": window[0] - session["channels_t0"], "to": window[1] - session["channels_t0"],
                               "params": os.path.basename(params_path) if args.params else
                               ("the parameters in the calibration report" if params_path else "the nominal model")}
                ctx["allan"] = readings
                ctx["allan_terms"] = allan_terms(curve, readings)
                ctx["allan_figure"] = allan_figure(curve, ctx["allan_terms"])
    finally:
        shutil.rmtree(work, ignore_errors=True)

    if spec is not None:
        ctx["spec"] = spec
        ctx["spec_rows"] = spec_rows(spec, report, ctx)
        ctx["overall"] = all(row["passed"] for row in ctx["spec_rows"])
    return ctx


def spec_rows(spec, report, ctx):
    terms = {t["key"]: t for t in ctx["allan_terms"]}
    rows = []
    if spec.get("require_accepted", True):
        rows.append({"key": "require_accepted", "limit": "true", "value": "accepted" if report["accepted"] else
                     "refused", "basis": "every quality gate of the calibration", "passed": bool(report["accepted"])})
    for key in sorted(k for k in spec if k in SPEC_KEYS):
        quantity, factor = SPEC_KEYS[key]
        limit = float(spec[key])
        value, basis, bound = None, "", False
        if quantity == "nonlinearity":
            if ctx["verification"] is not None:
                value, basis = ctx["verification"]["after_ppm"], "verification profile against ground truth"
            elif ctx["nonlinearity"]:
                value = ctx["nonlinearity"]["after_rms"]
                basis = "rms residual of the binned K about the fit (no verification profile given)"
        elif quantity == "harmonic_std":
            k_est = (report.get("scale_factor") or [None])[0]
            if k_est:
                stds = list(k_est["cos_std"]) + list(k_est["sin_std"])
                value, basis = 1e6 * max(stds) / abs(k_est["mean"]), "largest K harmonic standard error"
        elif quantity in terms:
            t = terms[quantity]
            if t["identified"]:
                value, basis = t["value"] * factor, t["how"]
            elif t["bound"] is not None:
                value, bound = t["bound"] * factor, True
                basis = "upper bound: not observable in the record"
        if value is None:
            rows.append({"key": key, "limit": fmt(limit, 4), "value": "not measured",
                         "basis": "the report has no data for it (no bag or no rest?)", "passed": False})
        else:
            rows.append({"key": key, "limit": fmt(limit, 4), "value": ("<= " if bound else "") + fmt(value, 4),
                         "basis": basis, "passed": value <= limit})
    return rows


def main(argv):
    parser = argparse.ArgumentParser(prog="hrg_report.py", description=__doc__.split("\n\n")[0],
                                     epilog="Specification YAML keys: %s. Unknown keys are refused." %
                                     ", ".join(sorted(list(SPEC_KEYS) + list(SPEC_OTHER_KEYS))))
    parser.add_argument("report", help="calibration report YAML")
    parser.add_argument("--out", required=True, help="HTML file to write")
    parser.add_argument("--bag", help="the session's bag: profile, temperature, Allan deviation at rest")
    parser.add_argument("--params", help="calibrated parameter file for the Allan deviation")
    parser.add_argument("--spec", metavar="LIMITS.yaml", help="specification YAML: pass/fail table")
    parser.add_argument("--verification", help="session_monitor summary YAML (before_ppm, after_ppm)")
    parser.add_argument("--rest", nargs=2, type=float, metavar=("FROM", "TO"),
                        help="channel stamps (s) of the rest for the Allan deviation (default: the longest)")
    parser.add_argument("--rest-max-rate", type=float, default=1e-5, metavar="RAD_S",
                        help="largest |table rate| counted as at rest (default 1e-5 rad/s)")
    parser.add_argument("--title", help="page title")
    args = parser.parse_args(argv[1:])
    for name in ("report", "bag", "params", "spec", "verification"):
        path = getattr(args, name)
        if path and not os.path.isfile(path):
            sys.stderr.write("hrg_report: --%s %s: no such file\n" % (name, path) if name != "report" else
                             "hrg_report: %s: no such file\n" % path)
            return 2
    try:
        ctx = build(args)
        html = render("report.html.j2", **ctx)
    except ReportError as e:
        sys.stderr.write("hrg_report: %s\n" % e)
        return 2
    try:
        write_atomically(args.out, html)
    except OSError as e:
        sys.stderr.write("hrg_report: %s\n" % e)
        return 3
    verdict = "" if ctx["overall"] is None else (" spec PASS" if ctx["overall"] else " spec FAIL")
    print("hrg_report: wrote %s (calibration %s%s)" % (args.out, "ACCEPTED" if ctx["r"]["accepted"] else "REFUSED",
                                                       verdict))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
