"""The alignment page of the HTML report (hrg_report.py): one or more results of `hrg_bag align --output`
(north-finding from the Earth's rate) drawn from their YAML alone. For each result: the heading against
the window length (the window's first S s solved alone, `hrg_bag align --windows`) with its 1-sigma
band and the law the full window's budget predicts, the residuals of the fit per segment (indexer
position, stretch between gaps), and the error budget. A module beside the scripts."""
import math
import os

from hrg_report_figures import figure_uri, plt
from hrg_report_validation import Fields, ReportError, load_yaml

BUDGET_TERMS = (  # key of budget_rad, what it is, how it goes with the window length T
    ("white_angle_noise", "white angle noise", "falls as T^-3/2"),
    ("angle_random_walk", "angle random walk", "falls as T^-1/2"),
    ("residual_bias", "residual bias of the calibration", "a floor (static); cancels on an indexer"),
    ("drift_harmonics", "D(theta) residual at the resting waves", "a floor (static); averaged by a sweep"),
    ("bias_random_walk", "bias random walk", "grows as T^1/2"),
    ("level", "level error about North, times tan(latitude)", "a floor"),
    ("indexer", "indexer angle errors", "a floor"),
)
# How each budget term goes with the window length T: its exponent of T / T0.
LAW_EXPONENTS = {"white_angle_noise": -1.5, "angle_random_walk": -0.5, "bias_random_walk": 0.5}


def is_alignment_result(path):
    """Whether `path` holds an alignment result (hrg_bag align --output) rather than a calibration
    report: a YAML map with heading_deg and budget_rad. Unreadable files are left to the caller's checks."""
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError:
        return False
    return b"\nheading_deg:" in head and b"# hrg_gyro alignment" in head


def load_alignment(path):
    """An alignment result, checked; a ReportError names the file and the key."""
    r = load_yaml(path, "alignment result")
    f = Fields(path)
    f.boolean(r, "accepted")
    for key in ("gate", "reason", "mode", "frame"):
        f.text(r, key)
    window = f.mapping(r, "window")
    for key in ("seconds",):
        f.number(window, key, "window", finite=True, minimum=0.0)
    f.count(window, "samples", "window")
    f.number(r, "heading_deg")
    f.number(r, "heading_sigma_deg")
    attitude = f.mapping(r, "attitude_rad")
    for key in ("roll", "pitch", "yaw"):
        f.number(attitude, key, "attitude_rad")
    budget = f.mapping(r, "budget_rad")
    for key, _, _ in BUDGET_TERMS:
        f.number(budget, key, "budget_rad")
    for key in ("noise", "total", "latitude_rad", "max_latitude_rad"):
        f.number(budget, key, "budget_rad")
    earth = f.mapping(r, "earth_rate")
    for key in ("horizontal_rad_s", "horizontal_std_rad_s", "expected_horizontal_rad_s"):
        f.number(earth, key, "earth_rate")
    f.number(r, "scatter")
    f.number(r, "worst_motion_rad_s")
    for here, s in f.items(r, "segments"):
        for key in ("start_s", "end_s", "indexer_angle_rad"):
            f.number(s, key, here)
        for key in ("residual_rate_rad_s", "residual_rate_std_rad_s", "rms_rad", "predicted_rms_rad"):
            f.numbers(s, key, here)
    for here, w in f.items(r, "windows"):
        f.boolean(w, "accepted", here)
        f.text(w, "gate", here)
        for key in ("window_s", "seconds", "heading_deg", "heading_sigma_deg", "noise_rad", "total_rad"):
            f.number(w, key, here)
    return r


def predicted_sigma(budget, t0, t):
    """The heading's 1 sigma (rad) at window length t by the law of the budget found over t0: each
    term scaled by (t / t0) to its exponent (LAW_EXPONENTS; the rest a floor)."""
    total = 0.0
    for key, _, _ in BUDGET_TERMS:
        term = budget[key]
        if math.isfinite(term):
            total += (term * (t / t0) ** LAW_EXPONENTS.get(key, 0.0)) ** 2
    return math.sqrt(total)


def legend(axes):
    if axes.get_legend_handles_labels()[0]:
        axes.legend(fontsize=8)


def heading_figure(name, r):
    """The heading against window length with its 1-sigma band, and the sigma against the law."""
    windows = [w for w in r["windows"] if w["accepted"]]
    t0 = r["window"]["seconds"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True)
    t = [w["window_s"] for w in windows]
    h = [w["heading_deg"] for w in windows]
    s = [w["heading_sigma_deg"] for w in windows]
    if windows:
        top.fill_between(t, [a - b for a, b in zip(h, s)], [a + b for a, b in zip(h, s)], color="#9ecae1",
                         label="1 sigma band")
        top.plot(t, h, "o-", color="#08519c", label="first T s alone")
    if r["accepted"]:
        top.errorbar([t0], [r["heading_deg"]], yerr=[r["heading_sigma_deg"]], fmt="s", color="#a50f15",
                     capsize=4, label="the window")
        top.axhline(r["heading_deg"], color="#a50f15", lw=0.8, ls=":")
    top.set_ylabel("true heading (deg)")
    top.set_title("%s: heading against window length" % name)
    legend(top)
    top.grid(True, alpha=0.3)
    if windows:
        bottom.loglog(t, [1e3 * math.radians(x) for x in s], "o", color="#08519c", label="reported sigma")
        # Each shorter window's departure from the whole window's heading (the whole window's own is 0).
        shorter = [(a, 1e3 * abs(math.radians(x - r["heading_deg"]))) for a, x in zip(t, h) if a < t0]
        shorter = [(a, e) for a, e in shorter if e > 0.0]
        if r["accepted"] and shorter:
            bottom.loglog([a for a, _ in shorter], [e for _, e in shorter], "x", color="#555555",
                          label="|heading - the window's|")
    if r["accepted"] and t0 > 0.0:
        lo = min(t + [t0]) if t else t0
        grid = [lo * (t0 / lo) ** (i / 40.0) for i in range(41)] if lo < t0 else [t0]
        bottom.loglog(grid, [1e3 * predicted_sigma(r["budget_rad"], t0, x) for x in grid], "-", color="#a50f15",
                      label="law of the window's budget")
    bottom.set_xlabel("window length T (s)")
    bottom.set_ylabel("heading 1 sigma (mrad)")
    legend(bottom)
    bottom.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return figure_uri(fig)


def residual_figure(name, r):
    """Each segment's residual rate per channel with its standard error."""
    segments = r["segments"]
    if not segments:
        return None
    fig, ax = plt.subplots(figsize=(7.5, 3.2))
    channels = max(len(s["residual_rate_rad_s"]) for s in segments)
    labels = "xyz" if channels == 3 else ["gyro"] * channels
    for c in range(channels):
        x = [i + 0.15 * (c - (channels - 1) / 2.0) for i, s in enumerate(segments) if c < len(s["residual_rate_rad_s"])]
        y = [1e9 * s["residual_rate_rad_s"][c] for s in segments if c < len(s["residual_rate_rad_s"])]
        e = [1e9 * s["residual_rate_std_rad_s"][c] for s in segments if c < len(s["residual_rate_std_rad_s"])]
        ax.errorbar(x, y, yerr=e, fmt="o", capsize=3, label="channel %s" % labels[c])
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set_xticks(range(len(segments)))
    ax.set_xticklabels([segment_label(s) for s in segments], fontsize=8)
    ax.set_ylabel("residual rate (nrad/s)")
    ax.set_title("%s: residuals of the fit per segment" % name)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return figure_uri(fig)


def segment_label(s):
    if math.isfinite(s["indexer_angle_rad"]):
        degrees = round(math.degrees(s["indexer_angle_rad"]), 1) + 0.0  # never "-0.0"
        return "%.0f-%.0f s, %.1f deg" % (s["start_s"], s["end_s"], degrees)
    return "%.0f-%.0f s" % (s["start_s"], s["end_s"])


def build_alignment(args, paths):
    """The context of the alignment page (templates/alignment_report.html.j2)."""
    for option in ("bag", "params", "verification", "rest", "spec"):
        if getattr(args, option, None):
            raise ReportError("--%s: an alignment page is drawn from the align results alone" % option)
    results = []
    for i, path in enumerate(paths):
        r = load_alignment(path)
        name = os.path.basename(path)
        budget = [{"key": key, "what": what, "law": law, "mrad": 1e3 * r["budget_rad"][key]}
                  for key, what, law in BUDGET_TERMS]
        results.append({"index": i, "name": name, "r": r, "budget": budget,
                        "segment_labels": [segment_label(s) for s in r["segments"]],
                        "heading_figure": heading_figure(name, r), "residual_figure": residual_figure(name, r)})
    title = args.title or "North-finding: " + ", ".join(os.path.basename(p) for p in paths)
    return {"title": title, "results": results, "overall": None}
