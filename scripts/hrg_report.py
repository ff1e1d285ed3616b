#!/usr/bin/env python3
"""One calibration as a self-contained HTML report a test engineer can sign.

  hrg_report.py REPORT.yaml --out OUT.html [--bag BAG] [--params CALIBRATED.yaml] [--spec LIMITS.yaml]
                [--verification SUMMARY.yaml] [--rest FROM TO] [--title TEXT]
  hrg_report.py ALIGNMENT.yaml [ALIGNMENT.yaml ...] --out OUT.html [--title TEXT]

REPORT.yaml is the calibration report (`hrg_bag calibrate --report`, or the calibrator node's
<parameter file>.<method>.report.yaml). A triad's report (method triad) gets a page of its own: the
axis matrix with its misalignment angles, the positions' responses, the body bias against the Earth's
rate and each axis's K(theta); it is drawn from the YAML alone (no --bag, --params, --verification).
A field calibration's report (method field: a still gyro whose precession loop turned the wave) shows
D(theta), the realised gain of the virtual rate G_v(theta) and says that K was kept from the prior. With --bag, the session's turntable profile and temperature
are drawn from the bag, and the Allan deviation of the compensated rate is computed over the bag's
longest rest (or --rest FROM TO, channel stamps in s) by `hrg_bag allan`, which runs the package's
processor with the calibrated parameters (--params, else the parameters in the report, else the
nominal model). --verification adds the before/after nonlinearity measured on a verification
profile against ground truth (session_monitor's summary YAML, as `make run` writes it). --spec
checks the figures against the gyro's specification (see SPEC_KEYS).

ALIGNMENT.yaml, one or more results of `hrg_bag align --output` (north-finding), give the alignment page
instead (hrg_report_alignment.py): per result the heading against window length with its 1-sigma band
and the law of its budget, the residuals per segment and the error budget, from the YAML alone.

Everything the page shows is embedded (PNG figures as data URIs, styles inline): it opens offline
and prints on A4. The page is written as the package's C++ tools write their outputs
(hrg_output_file.py): whole or not at all, a link at --out followed, the mode of a replaced file kept.

Exit codes:
  0  the report was written (whatever the pass/fail)
  2  bad usage or input, nothing written: a missing input or one that is not a regular file; --out
     the same file as an input (also through a link, a hard link or another spelling) or an existing
     FIFO, device or directory; a YAML input with a key given twice, or a calibration report,
     specification or verification summary with a missing or malformed field (the message names the
     file and the key path)
  3  the report could not be written (full disk...): no temporary left, an existing file unchanged

The script is its command line and the page; its inputs are checked in hrg_report_validation.py, its
figures drawn in hrg_report_figures.py (modules beside it).
"""
import argparse
import datetime
import math
import os
import shutil
import signal
import stat
import sys
import tempfile

# The modules beside this script. Its own folder first: run through catkin's devel-space relay,
# sys.path[0] is the relay's folder, and __file__ is this source file.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_output_file  # noqa: E402
from hrg_models import one_line  # noqa: E402
from hrg_report_figures import (allan_figure, allan_terms, fmt, longest_rest, model_figure,  # noqa: E402
                                profile_figure, read_session, run_allan, temperature_figure, triad_axis_figures)
from hrg_report_alignment import build_alignment, is_alignment_result  # noqa: E402
from hrg_report_validation import (RAD_S_TO_DEG_H, SPEC_KEYS, SPEC_OTHER_KEYS, TRIAD_SPEC_KEYS,  # noqa: E402
                                   ReportError, load_report, load_spec, load_verification)


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
    # A direction's or an angle's components: rounding noise (1e-16 of a rotation) shown as 0.
    env.filters["axis"] = lambda v: fmt(0.0 if abs(v) < 1e-12 else v, 4)
    return env.get_template(template_name).render(**context)


def build_triad(args, report):
    """The context of the triad page (templates/triad_report.html.j2)."""
    for option in ("bag", "params", "verification", "rest"):
        if getattr(args, option):
            raise ReportError("--%s: a triad report is drawn from its YAML alone (the single-axis page reads "
                              "a bag, parameters and a verification summary; run it per axis)" % option)
    spec = load_spec(args.spec) if args.spec else None
    band_sigma = 1.96
    a = report["body_to_axis"]
    a_std = report["body_to_axis_std"]
    names = report["axes"]
    misalignment = []  # the off-diagonal entries of A: axis i tilted towards body axis j, in urad
    for i in range(3):
        for j in range(3):
            if i != j:
                misalignment.append({"axis": names[i], "towards": "xyz"[j], "i": i, "j": j,
                                     "urad": 1e6 * a[i][j], "std_urad": 1e6 * a_std[i][j]})
    scales = [{"axis": names[i], "i": i, "ppm": 1e6 * (a[i][i] - 1.0), "std_ppm": 1e6 * a_std[i][i]}
              for i in range(3)]
    ctx = {"title": args.title or "Triad calibration report: " + os.path.basename(args.report),
           "generated": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "report_path": os.path.basename(args.report), "r": report, "band_sigma": band_sigma,
           "misalignment": misalignment, "scales": scales, "rad_s_to_deg_h": RAD_S_TO_DEG_H,
           "axes": [triad_axis_figures(report, n, band_sigma) for n in names],
           "spec": None, "spec_rows": [], "overall": None}
    if spec is not None:
        ctx["spec"] = spec
        ctx["spec_rows"] = triad_spec_rows(spec, report, ctx)
        ctx["overall"] = all(row["passed"] for row in ctx["spec_rows"])
    return ctx


def triad_spec_rows(spec, report, ctx):
    rows = []
    if spec.get("require_accepted", True):
        rows.append({"key": "require_accepted", "limit": "true", "value": "accepted" if report["accepted"] else
                     "refused", "basis": "every quality gate of the triad and of its three axes",
                     "passed": bool(report["accepted"])})
    for key in sorted(k for k in spec if k in SPEC_KEYS or k in TRIAD_SPEC_KEYS):
        quantity, factor = SPEC_KEYS.get(key) or TRIAD_SPEC_KEYS[key]
        limit = float(spec[key])
        value, basis = None, ""
        if quantity == "nonlinearity":
            values = [x["after_rms"] for x in ctx["axes"] if x["after_rms"] is not None]
            if len(values) == 3:
                value, basis = max(values), "worst axis: rms residual of its binned K about the fit"
        elif quantity == "harmonic_std":
            worst = None
            for x in ctx["axes"]:
                k_est = (x["r"].get("scale_factor") or [None])[0]
                stds = list(k_est["cos_std"]) + list(k_est["sin_std"]) if k_est else []
                if stds:
                    ppm = 1e6 * max(stds) / abs(k_est["mean"])
                    worst = ppm if worst is None else max(worst, ppm)
            if worst is not None:
                value, basis = worst, "worst axis: largest K harmonic standard error"
        elif report["positions_fitted"] > 0 and quantity == "misalignment":
            value = max(abs(m["urad"]) for m in ctx["misalignment"]) / 1e6 * factor
            basis = "largest off-diagonal entry of A = M^-1 (an axis's tilt towards another body axis)"
        elif report["positions_fitted"] > 0 and quantity == "misalignment_std":
            value = max(m["std_urad"] for m in ctx["misalignment"]) / 1e6 * factor
            basis = "largest standard error of the off-diagonal entries of A"
        elif report["bias_estimated"] and quantity == "body_bias_std":
            value, basis = max(report["bias_std"]) * factor, "largest standard error of the body bias"
        if value is None:
            rows.append({"key": key, "limit": fmt(limit, 4), "value": "not measured",
                         "basis": "not in a triad report" if key in SPEC_KEYS and quantity not in
                         ("nonlinearity", "harmonic_std") else "the report has no data for it", "passed": False})
        else:
            rows.append({"key": key, "limit": fmt(limit, 4), "value": fmt(value, 4), "basis": basis,
                         "passed": value <= limit})
    return rows


def build(args):
    alignments = [is_alignment_result(path) for path in args.report]
    if any(alignments):
        if not all(alignments):
            raise ReportError("%s: an alignment result and a calibration report do not share a page" %
                              args.report[alignments.index(False)])
        return build_alignment(args, args.report)
    if len(args.report) != 1:
        raise ReportError("one calibration report per page (several files are for alignment results)")
    args.report = args.report[0]
    report = load_report(args.report)
    if report["method"] == "triad":
        return build_triad(args, report)
    spec = load_spec(args.spec) if args.spec else None
    verification = load_verification(args.verification) if args.verification else None
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
           "field": None,
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
    if "field" in report:
        # The binned k of a field session is the realised gain of the virtual rate, G_v(theta).
        gain = report["field"]["virtual_rate_gain"]
        ctx["field"] = {"gain_rows": harmonic_rows(gain, gain["mean"]),
                        "gain_figure": model_figure(theta, binned.get("k"), gain, gain["mean"], None,
                                                    "G_v / G_v0 - 1 (ppm)", band_sigma)}

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
    for key in sorted(k for k in spec if k in SPEC_KEYS or k in TRIAD_SPEC_KEYS):
        quantity, factor = SPEC_KEYS.get(key) or TRIAD_SPEC_KEYS[key]
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
            stds = list(k_est["cos_std"]) + list(k_est["sin_std"]) if k_est else []
            if stds:  # a K0-only fit has no harmonic to compare: not measured
                value, basis = 1e6 * max(stds) / abs(k_est["mean"]), "largest K harmonic standard error"
        elif quantity in ("misalignment", "misalignment_std", "body_bias_std"):
            rows.append({"key": key, "limit": fmt(limit, 4), "value": "not measured",
                         "basis": "a triad's figure: this is a single axis's report", "passed": False})
            continue
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
                                     epilog="Specification YAML keys: %s (the max_misalignment and max_body_bias keys for a triad's "
                                     "report). Unknown keys are refused. Exit 0 the "
                                     "page was written, 2 bad usage or input (nothing written), 3 the page could "
                                     "not be written." % ", ".join(sorted(list(SPEC_KEYS) + list(TRIAD_SPEC_KEYS) + list(SPEC_OTHER_KEYS))))
    parser.add_argument("report", nargs="+",
                        help="calibration report YAML, or one or more alignment results (hrg_bag align --output)")
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
    try:
        return run(args)
    except KeyboardInterrupt:
        sys.stderr.write("hrg_report: interrupted: %s not written\n" % args.out)
        return 130
    except Exception as e:  # last resort: a one-line error, never a traceback
        sys.stderr.write("hrg_report: %s not written: unexpected %s: %s\n" % (args.out, type(e).__name__,
                                                                              one_line(e)))
        return 2


def run(args):
    inputs = []
    named = [("report", p) for p in args.report] + [(n, getattr(args, n)) for n in ("bag", "params", "spec",
                                                                                    "verification")]
    for name, path in named:
        if not path:
            continue
        what = path if name == "report" else "--%s %s" % (name, path)
        try:
            st = os.stat(path)
        except FileNotFoundError:
            sys.stderr.write("hrg_report: %s: no such file\n" % what)
            return 2
        except OSError as e:
            sys.stderr.write("hrg_report: %s: %s\n" % (what, e.strerror))
            return 2
        if not stat.S_ISREG(st.st_mode):  # never opened: a FIFO would block the read
            sys.stderr.write("hrg_report: %s is %s, not a regular file\n" % (what, hrg_output_file.kind_of(st.st_mode)))
            return 2
        inputs.append(path)
    try:
        hrg_output_file.check_output_paths(inputs, [args.out])
    except hrg_output_file.PathRefused as e:
        sys.stderr.write("hrg_report: refused: %s\n" % e)
        return 2
    try:
        ctx = build(args)
        if "results" in ctx:
            html = render("alignment_report.html.j2", **ctx)
        else:
            html = render("triad_report.html.j2" if ctx["r"]["method"] == "triad" else "report.html.j2", **ctx)
    except ReportError as e:
        sys.stderr.write("hrg_report: %s\n" % e)
        return 2
    try:
        hrg_output_file.write_file_atomically(args.out, html)
    except hrg_output_file.OutputWriteError as e:
        sys.stderr.write("hrg_report: report %s not written: %s\n" % (args.out, e))
        return 3
    if "results" in ctx:
        print("hrg_report: wrote %s (alignment: %s)" % (args.out, ", ".join(
            "%s %s" % (x["name"], "ACCEPTED" if x["r"]["accepted"] else "REFUSED (%s)" % x["r"]["gate"])
            for x in ctx["results"])))
        return 0
    verdict = "" if ctx["overall"] is None else (" spec PASS" if ctx["overall"] else " spec FAIL")
    print("hrg_report: wrote %s (calibration %s%s)" % (args.out, "ACCEPTED" if ctx["r"]["accepted"] else "REFUSED",
                                                       verdict))
    return 0


if __name__ == "__main__":
    # SIGTERM unwinds like an exception, so that the page's temporary is removed.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    sys.exit(main(sys.argv))
