"""The inputs of the HTML calibration report (hrg_report.py), read and checked before anything is
drawn: the calibration report (single axis or triad), the specification and the verification summary.
A hand-edited or damaged input is refused (ReportError) naming the file and the key path instead of
ending in a traceback; fields the page does not read are not checked. A module beside the scripts."""
import math

from hrg_models import YamlFileError, read_yaml
from hrg_output_file import shown

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


class ReportError(Exception):
    """Bad usage or input: message printed, exit 2."""


def load_yaml(path, what):
    """The YAML map in `path` (hrg_models.read_yaml), ReportError otherwise."""
    try:
        return read_yaml(path, what)
    except YamlFileError as e:
        raise ReportError(str(e))


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
# The calibration report: every field the page or its figures read.

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

    def typed(self, m, key, prefix, ok, what):
        """The value at `key`, refused as not `what` unless ok(value)."""
        value = self.get(m, key, prefix)
        if not ok(value):
            self.fail(self.path(prefix, key), what, value)
        return value

    def count(self, m, key, prefix="", minimum=0):
        return self.typed(m, key, prefix,
                          lambda v: not isinstance(v, bool) and isinstance(v, int) and v >= minimum,
                          "a whole number >= %d" % minimum)

    def boolean(self, m, key, prefix=""):
        return self.typed(m, key, prefix, lambda v: isinstance(v, bool), "true or false (a YAML boolean)")

    def text(self, m, key, prefix=""):
        return self.typed(m, key, prefix, lambda v: isinstance(v, str), "text")

    def mapping(self, m, key, prefix=""):
        return self.typed(m, key, prefix, lambda v: isinstance(v, dict), "a map")

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
