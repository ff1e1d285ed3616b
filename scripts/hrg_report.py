#!/usr/bin/env python3
"""One calibration as a self-contained HTML report a test engineer can sign.

  hrg_report.py REPORT.yaml --out OUT.html [--bag BAG] [--params CALIBRATED.yaml] [--spec LIMITS.yaml]
                [--verification SUMMARY.yaml] [--rest FROM TO] [--title TEXT]

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
import signal
import stat
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import yaml  # noqa: E402

# The shared writer beside this script. Its own folder first: run through catkin's devel-space relay,
# sys.path[0] is the relay's folder, and __file__ is this source file.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hrg_output_file  # noqa: E402
from hrg_output_file import shown  # noqa: E402

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
# A triad's own figures (a triad report only; on a single axis they are "not measured").
TRIAD_SPEC_KEYS = {
    "max_misalignment_urad": ("misalignment", 1e6),
    "max_misalignment_std_urad": ("misalignment_std", 1e6),
    "max_body_bias_std_rad_per_s": ("body_bias_std", 1.0),
    "max_body_bias_std_deg_per_h": ("body_bias_std", RAD_S_TO_DEG_H),
}
SPEC_OTHER_KEYS = {"name", "require_accepted"}

MIN_CLUSTERS = 9  # Allan points with fewer independent clusters are drawn, not read (as the core does)
MAX_YAML_BYTES = 16 << 20  # a calibration report is well below 1 MiB; larger is not one


class DuplicateKeyError(yaml.YAMLError):
    pass


class Loader(yaml.SafeLoader):
    """YAML 1.2 numbers: yaml-cpp writes 1e-05, which PyYAML's YAML 1.1 rules would read as a string.
    A key given twice in one map is refused, as the package's C++ reader refuses it: PyYAML would
    silently keep the last one (a limit typed twice would drop the first)."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            first_line = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue  # "<<: *base": keys given beside it override the merged ones
                key = self.construct_object(key_node, deep=True)
                try:
                    line = first_line.get(key)
                except TypeError:
                    continue  # an unhashable key: SafeLoader refuses it with its own message
                if line is not None:
                    raise DuplicateKeyError("key %s given more than once in the same map (lines %d and %d)" %
                                            (shown(key), line + 1, key_node.start_mark.line + 1))
                first_line[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep)


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


def one_line(text, limit=300):
    """A message on one line, cut to `limit` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else "%s... (%d characters)" % (text[:limit], len(text))


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
    """The YAML map in `path`: a regular file of at most MAX_YAML_BYTES, UTF-8, no key given twice."""
    try:
        raw = hrg_output_file.read_regular_file(path, what, MAX_YAML_BYTES)
    except hrg_output_file.PathRefused as e:
        raise ReportError(str(e))
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ReportError("cannot read %s %s: not UTF-8 text (byte %d)" % (what, path, e.start))
    stream = io.StringIO(text)
    stream.name = path  # PyYAML's messages name the file
    try:
        data = yaml.load(stream, Loader=Loader)
    except DuplicateKeyError as e:
        raise ReportError("%s %s: %s" % (what, path, e))
    except yaml.YAMLError as e:
        raise ReportError("cannot read %s %s: %s" % (what, path, one_line(e)))
    except RecursionError:
        raise ReportError("cannot read %s %s: nested too deeply" % (what, path))
    if not isinstance(data, dict):
        raise ReportError("%s %s is not a YAML map" % (what, path))
    return data


def positive_number(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return 0.0 < float(value) < math.inf
    except OverflowError:  # an integer beyond any double
        return False


def load_spec(path):
    spec = load_yaml(path, "--spec")
    for key, value in spec.items():
        if key not in SPEC_KEYS and key not in TRIAD_SPEC_KEYS and key not in SPEC_OTHER_KEYS:
            raise ReportError("--spec %s: unknown key %s (known: %s)" %
                              (path, shown(key), ", ".join(sorted(list(SPEC_KEYS) + list(TRIAD_SPEC_KEYS) +
                                                                  list(SPEC_OTHER_KEYS)))))
        if (key in SPEC_KEYS or key in TRIAD_SPEC_KEYS) and not positive_number(value):
            raise ReportError("--spec %s: '%s' must be a positive number, not %s" % (path, key, shown(value)))
        if key == "require_accepted" and not isinstance(value, bool):
            raise ReportError("--spec %s: 'require_accepted' must be true or false, not %s" % (path, shown(value)))
        if key == "name" and value is not None:  # "name:" left empty: no name
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                spec[key] = str(value)  # a part number given as a number
            elif not isinstance(value, str):
                raise ReportError("--spec %s: 'name' must be text, not %s" % (path, shown(value)))
    return spec


# ---------------------------------------------------------------------------------------------
# The calibration report: every field the page or its figures read, checked before anything is
# drawn, so that a hand-edited or damaged report is refused naming the key path instead of ending in
# a traceback. Fields the page does not read are not checked.

# yaml-cpp writes non-finite doubles as nan / inf / -inf, which YAML (1.1 and 1.2) reads as text.
NON_FINITE = {"nan": math.nan, "-nan": math.nan, "inf": math.inf, "+inf": math.inf, "-inf": -math.inf}


class Fields:
    """Typed reads of a YAML tree; every refusal names the file and the key path. Numbers are
    normalised to float in place (the page formats them with %g)."""

    def __init__(self, where):
        self.where = where

    def fail(self, path, rule, value):
        raise ReportError("%s: %s: must be %s, not %s" % (self.where, path, rule, shown(value)))

    @staticmethod
    def path(prefix, key):
        if isinstance(key, int):
            return "%s[%d]" % (prefix, key)
        return "%s.%s" % (prefix, key) if prefix else key

    def get(self, m, key, prefix):
        if isinstance(m, list):
            return m[key]
        if key not in m:
            raise ReportError("%s: %s: missing" % (self.where, self.path(prefix, key)))
        return m[key]

    def number(self, m, key, prefix="", finite=False, nonzero=False, minimum=None, optional=False):
        if optional and key not in m:
            return None
        value = self.get(m, key, prefix)
        rule = ("a non-zero finite number" if nonzero else
                "a finite number >= %g" % minimum if minimum is not None else
                "a finite number" if finite else "a number")
        if isinstance(value, str) and value.strip().lower() in NON_FINITE:
            value = NON_FINITE[value.strip().lower()]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(self.path(prefix, key), rule, value)
        try:
            number = float(value)
        except OverflowError:  # an integer beyond any double
            self.fail(self.path(prefix, key), rule, value)
        if (finite or nonzero or minimum is not None) and not math.isfinite(number):
            self.fail(self.path(prefix, key), rule, value)
        if (nonzero and number == 0.0) or (minimum is not None and number < minimum):
            self.fail(self.path(prefix, key), rule, value)
        m[key] = number
        return number

    def count(self, m, key, prefix="", minimum=0):
        value = self.get(m, key, prefix)
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            self.fail(self.path(prefix, key), "a whole number >= %d" % minimum, value)
        return value

    def boolean(self, m, key, prefix=""):
        value = self.get(m, key, prefix)
        if not isinstance(value, bool):
            self.fail(self.path(prefix, key), "true or false (a YAML boolean)", value)
        return value

    def text(self, m, key, prefix=""):
        value = self.get(m, key, prefix)
        if not isinstance(value, str):
            self.fail(self.path(prefix, key), "text", value)
        return value

    def mapping(self, m, key, prefix=""):
        value = self.get(m, key, prefix)
        if not isinstance(value, dict):
            self.fail(self.path(prefix, key), "a map", value)
        return value

    def items(self, m, key, prefix=""):
        """The entries of a list of maps, each with its key path."""
        value = self.get(m, key, prefix)
        if not isinstance(value, list):
            self.fail(self.path(prefix, key), "a list", value)
        here = self.path(prefix, key)
        for i, item in enumerate(value):
            if not isinstance(item, dict):
                self.fail(self.path(here, i), "a map", item)
        return [(self.path(here, i), item) for i, item in enumerate(value)]

    def numbers(self, m, key, prefix="", length=None, optional=False, **rule):
        """A list of numbers; with length=(n, what), exactly n of them, as many as `what` has."""
        if optional and key not in m:
            return None
        value = self.get(m, key, prefix)
        here = self.path(prefix, key)
        if not isinstance(value, list):
            self.fail(here, "a list of numbers", value)
        if length is not None and len(value) != length[0]:
            raise ReportError("%s: %s: must have %d entries, as many as %s, not %d" %
                              (self.where, here, length[0], length[1], len(value)))
        for i in range(len(value)):
            self.number(value, i, here, **rule)
        return value


def validate_report(report, path):
    """Refuses (ReportError naming the key path) a calibration report the page cannot show."""
    f = Fields("calibration report %s" % path)
    f.text(report, "method")
    f.boolean(report, "accepted")  # "no" in quotes is text, and text is true in Python: refuse it
    f.text(report, "reason")
    for key in ("coverage", "smoothing_factor", "nonlinearity_ppm", "duration"):
        f.number(report, key)
    f.count(report, "samples")
    f.numbers(report, "frequency_nodes", optional=True)
    def harmonic_fit(fit, here, nonzero=False):
        orders = f.get(fit, "orders", here)
        if not isinstance(orders, list):
            f.fail(f.path(here, "orders"), "a list of whole numbers", orders)
        for i in range(len(orders)):
            f.count(orders, i, f.path(here, "orders"), minimum=1)
        f.number(fit, "frequency", here, optional=True)
        # K0 divides every figure in ppm: zero or non-finite would end in a division by zero or NaNs.
        f.number(fit, "mean", here, finite=True, nonzero=nonzero)
        f.number(fit, "mean_std", here, minimum=0.0)
        length = (len(orders), f.path(here, "orders"))
        for key in ("cos", "sin"):
            f.numbers(fit, key, here, length=length, finite=True)
        for key in ("cos_std", "sin_std"):
            f.numbers(fit, key, here, length=length, minimum=0.0)
        f.number(fit, "residual_rms", here, minimum=0.0)
        f.count(fit, "points", here)

    for part in ("scale_factor", "drift"):
        for here, fit in f.items(report, part):
            harmonic_fit(fit, here, nonzero=part == "scale_factor")
    # The virtual rotation of a still gyro: the section comes with every field calibration whose fit
    # ran (a refused one may end before it: one direction only, a thermal prior).
    if "field" in report or (report["method"] == "field" and report["accepted"] is True):
        field = f.mapping(report, "field")
        # The gain divides the amplitudes in ppm: zero would end in a division by zero.
        harmonic_fit(f.mapping(field, "virtual_rate_gain", "field"), "field.virtual_rate_gain", nonzero=True)
        harmonic_fit(f.mapping(field, "measured_drift", "field"), "field.measured_drift")
        for key in ("earth_rate", "k0_prior", "positive_rate", "negative_rate", "positive_turns", "negative_turns",
                    "positive_time", "negative_time", "excess_scatter"):
            f.number(field, key, "field", finite=True)
    f.count(report, "turntable_records")
    rejected = f.mapping(report, "turntable_rejected")
    for key in rejected:
        if not isinstance(key, str):
            f.fail("turntable_rejected", "a map of reasons (text) to counts", key)
        f.count(rejected, key, "turntable_rejected")
    f.count(report, "restarts")
    if "bias_trend" in report:  # dual-rate: the bias's trend fitted with K and D
        trend = f.mapping(report, "bias_trend")
        order = f.count(trend, "order", "bias_trend", minimum=1)
        for key in ("coefficients", "coefficients_std"):
            f.numbers(trend, key, "bias_trend", length=(order, "bias_trend.order"), finite=True)
        for key in ("reference_stamp", "span", "change_over_span", "k0_inflation", "k0_correlation"):
            f.number(trend, key, "bias_trend", finite=True)
    if "table_clock" in report:  # the table's clock against the gyro's
        clock = f.mapping(report, "table_clock")
        for key in ("regularised", "offset_estimated", "offset_changed", "rate_error_estimated"):
            f.boolean(clock, key, "table_clock")
        for key in ("records", "regularised_records", "off_line_records", "clock_steps"):
            f.count(clock, key, "table_clock")
        for key in ("configured_offset", "log_period", "jitter", "offset", "offset_std", "offset_spread", "rate_error",
                    "rate_error_std", "k_scaled"):
            f.number(clock, key, "table_clock", finite=True)
        f.text(clock, "counted_by", "table_clock")
        f.text(clock, "offset_note", "table_clock")
        for here, t in f.items(clock, "transitions", "table_clock"):
            for key in ("stamp", "rate_before", "rate_after", "offset", "offset_noise"):
                f.number(t, key, here, finite=True)
    for here, plateau in f.items(report, "plateaus"):
        for key in ("rate", "rate_std", "duration", "coverage", "turns"):
            f.number(plateau, key, here)
        f.count(plateau, "samples", here)
    for here, d in f.items(report, "diagnosis"):
        f.text(d, "note", here)
        if f.boolean(d, "valid", here):
            for key in ("gain_mismatch", "gain_mismatch_std", "misplacement_difference",
                        "misplacement_difference_std", "pickoff_ratio", "pickoff_ratio_std"):
                f.number(d, key, here)
            f.numbers(d, "recommended_p", here)
            f.numbers(d, "current_p", here)
    for here, gate in f.items(report, "gates"):
        f.text(gate, "name", here)
        f.boolean(gate, "passed", here)
        f.number(gate, "value", here)
        f.number(gate, "limit", here)
        f.text(gate, "message", here)
    notes = f.get(report, "notes", "")
    if not isinstance(notes, list):
        f.fail("notes", "a list of text", notes)
    for i, note in enumerate(notes):
        if not isinstance(note, str):
            f.fail(f.path("notes", i), "text", note)
    binned = f.mapping(report, "binned")
    theta = f.numbers(binned, "theta", "binned")
    for key in ("k", "d"):
        f.numbers(binned, key, "binned", length=(len(theta), "binned.theta"))
    f.text(report, "parameters")
    return report


def validate_triad_report(report, path):
    """Refuses (ReportError naming the key path) a triad calibration report the page cannot show;
    each axis's own report inside it is checked as a single-axis one."""
    f = Fields("triad calibration report %s" % path)
    f.text(report, "method")
    f.boolean(report, "accepted")
    f.text(report, "reason")
    f.text(report, "frame_id")
    axes = f.get(report, "axes", "")
    if not (isinstance(axes, list) and len(axes) == 3 and all(isinstance(a, str) and a for a in axes)
            and len(set(axes)) == 3):
        f.fail("axes", "a list of three distinct axis names", axes)

    def vector(m, key, prefix="", **rule):
        return f.numbers(m, key, prefix, length=(3, "axes"), **rule)

    for key in ("axis_to_body", "axis_to_body_std", "body_to_axis", "body_to_axis_std"):
        rows = f.get(report, key, "")
        if not isinstance(rows, list) or len(rows) != 3:
            f.fail(key, "a 3x3 matrix (three rows of three numbers)", rows)
        for i in range(3):
            vector(rows, i, key, **({"minimum": 0.0} if key.endswith("_std") else {"finite": True}))
    vector(report, "fit_chi_square")
    f.count(report, "positions_fitted")
    f.boolean(report, "bias_estimated")
    vector(report, "bias", finite=True)
    vector(report, "bias_std", minimum=0.0)
    for here, p in f.items(report, "positions"):
        f.count(p, "position", here)
        f.text(p, "name", here)
        vector(p, "table_axis", here, finite=True)
        vector(p, "response", here, finite=True)
        vector(p, "response_std", here, minimum=0.0)
        f.number(p, "duration", here, minimum=0.0)
        f.count(p, "increments", here)
    for here, r in f.items(report, "rests"):
        f.count(r, "position", here)
        f.text(r, "name", here)
        f.number(r, "table_angle", here, finite=True)
        for key in ("axis_rates", "earth_body", "bias"):
            vector(r, key, here, finite=True)
        vector(r, "axis_rates_std", here, minimum=0.0)
        f.number(r, "duration", here, minimum=0.0)
    for here, gate in f.items(report, "gates"):
        f.text(gate, "name", here)
        f.boolean(gate, "passed", here)
        f.number(gate, "value", here)
        f.number(gate, "limit", here)
        f.text(gate, "message", here)
    notes = f.get(report, "notes", "")
    if not isinstance(notes, list) or not all(isinstance(n, str) for n in notes):
        f.fail("notes", "a list of text", notes)
    axis_reports = f.mapping(report, "axis_reports")
    for name in axes:
        f.mapping(axis_reports, name, "axis_reports")
        validate_report(axis_reports[name], "%s, axis_reports.%s" % (path, name))
    f.text(report, "triad_file")
    return report


def load_report(path):
    report = load_yaml(path, "calibration report")
    for key in ("method", "accepted"):
        if key not in report:
            raise ReportError("%s is not a calibration report: no '%s' key" % (path, key))
    if report["method"] == "triad":
        return validate_triad_report(report, path)
    return validate_report(report, path)


def load_verification(path):
    verification = load_yaml(path, "--verification")
    f = Fields("--verification %s" % path)
    for key in ("before_ppm", "after_ppm"):
        if key not in verification:
            raise ReportError("--verification %s: no '%s' key (session_monitor's summary YAML)" % (path, key))
        # NaN is what session_monitor writes when the verification could not be evaluated: shown, and
        # a specification limit compared with it fails.
        f.number(verification, key)
    f.number(verification, "after_sigma_ppm", optional=True)
    return verification


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
    # A direction's or an angle's components: rounding noise (1e-16 of a rotation) shown as 0.
    env.filters["axis"] = lambda v: fmt(0.0 if abs(v) < 1e-12 else v, 4)
    return env.get_template(template_name).render(**context)


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
    for name in ("report", "bag", "params", "spec", "verification"):
        path = getattr(args, name)
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
        html = render("triad_report.html.j2" if ctx["r"]["method"] == "triad" else "report.html.j2", **ctx)
    except ReportError as e:
        sys.stderr.write("hrg_report: %s\n" % e)
        return 2
    try:
        hrg_output_file.write_file_atomically(args.out, html)
    except hrg_output_file.OutputWriteError as e:
        sys.stderr.write("hrg_report: report %s not written: %s\n" % (args.out, e))
        return 3
    verdict = "" if ctx["overall"] is None else (" spec PASS" if ctx["overall"] else " spec FAIL")
    print("hrg_report: wrote %s (calibration %s%s)" % (args.out, "ACCEPTED" if ctx["r"]["accepted"] else "REFUSED",
                                                       verdict))
    return 0


if __name__ == "__main__":
    # SIGTERM unwinds like an exception, so that the page's temporary is removed.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    sys.exit(main(sys.argv))
