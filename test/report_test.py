#!/usr/bin/env python3
"""The HTML calibration report and the batch campaign, looked at as a person would: the page is
rendered by headless Chromium, must load with no console error and every figure decoded, and the
numbers the browser shows must equal those of the calibration report YAML. The Allan readings are
checked against a simulated gyro whose angle random walk is known. The scripts' file handling is
checked as the C++ tools' is: an output that is an input or not a regular file is refused, links and
modes are kept, a full disk leaves nothing behind, malformed inputs are refused naming the key.
Needs no master; run as a rostest for the package environment."""
import errno
import html.parser
import math
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import time
import unittest

import rospy
import rostest
import yaml

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
ARW = 1.0e-4  # rad/sqrt(s), resonator.rate_noise of test/scenarios/report_session.yaml


def run(*args, timeout=600, **kwargs):
    p = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                       timeout=timeout, **kwargs)
    return p.returncode, p.stdout, p.stderr


def snapshot(directory):
    """Every name under `directory` with its content, mode and inode (links as links): what a refused
    or failed write must not change. Temporaries left behind show up as new names."""
    state = {}
    for root, dirs, files in os.walk(directory):
        for name in dirs + files:
            path = os.path.join(root, name)
            st = os.lstat(path)
            key = os.path.relpath(path, directory)
            if stat.S_ISLNK(st.st_mode):
                state[key] = ("link", os.readlink(path))
            elif stat.S_ISREG(st.st_mode):
                with open(path, "rb") as f:
                    state[key] = ("file", f.read(), st.st_mode, st.st_ino)
            else:
                state[key] = ("other", stat.S_IFMT(st.st_mode), st.st_mode, st.st_ino)
    return state


def temporaries(directory):
    """Writer temporaries (<name>.tmp.<pid>.XXXXXX) anywhere under `directory`."""
    return [os.path.join(root, n) for root, _, files in os.walk(directory) for n in files if ".tmp." in n]


def fill(directory, leave_bytes):
    """Fills the file system of `directory` until at most `leave_bytes` are free (as hrg_bag_cli_test)."""
    filler = os.path.join(directory, "filler")
    st = os.statvfs(directory)
    with open(filler, "ab") as f:
        try:
            f.write(b"\0" * max(0, st.f_bavail * st.f_frsize - leave_bytes))
            f.flush()
            os.fsync(f.fileno())
        except OSError as e:
            if e.errno != errno.ENOSPC:
                raise
    return filler


class Page(html.parser.HTMLParser):
    """The rendered DOM: text of every element carrying data-q or id, and the body's attributes."""

    def __init__(self):
        super().__init__()
        self.stack, self.by_q, self.by_id, self.body, self.links = [], {}, {}, {}, []
        self.scale = {}  # data-q -> the factor the page applied (data-scale)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "body":
            self.body = a
        if a.get("data-q") and a.get("data-scale"):
            self.scale[a["data-q"]] = float(a["data-scale"])
        for name in ("src", "href"):
            if a.get(name):
                self.links.append(a[name])
        if tag in ("meta", "img", "br", "link"):
            return
        self.stack.append([a.get("data-q"), a.get("id"), ""])

    def handle_endtag(self, tag):
        if tag in ("meta", "img", "br", "link") or not self.stack:
            return
        q, i, text = self.stack.pop()
        if self.stack:
            self.stack[-1][2] += text
        if q:
            self.by_q[q] = text.strip()
        if i:
            self.by_id[i] = text.strip()

    def handle_data(self, data):
        if self.stack:
            self.stack[-1][2] += data


def lookup(report, path):
    value = report
    for part in path.split("."):
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def render(html_path, work):
    """Chromium's DOM of the page, with a probe appended that records decoded images and errors."""
    probe = os.path.join(work, "probe_" + os.path.basename(html_path))
    with open(html_path) as f:
        text = f.read()
    script = ('<script>window.addEventListener("load", () => { const i = [...document.images]; '
              'document.body.setAttribute("data-images", i.filter(x => x.complete && x.naturalWidth > 0).length '
              '+ "/" + i.length); });</script></body>')
    with open(probe, "w") as f:
        f.write(text.replace("</body>", script))
    code, dom, err = run("chromium", "--headless", "--disable-gpu", "--no-sandbox", "--enable-logging=stderr",
                         "--v=0", "--virtual-time-budget=5000", "--dump-dom", "file://" + probe, timeout=120)
    page = Page()
    page.feed(dom)
    return code, page, err


class ReportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "report")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.pkg = rospy.get_param("~package_dir")
        cls.script = os.path.join(cls.pkg, "scripts", "hrg_report.py")
        sys.path.insert(0, os.path.join(cls.pkg, "scripts"))
        cls.models_module = __import__("hrg_models")  # the scripts' YAML loader reads 1e-05 as yaml-cpp means it
        cls.prior = os.path.join(cls.pkg, "config", "params_uncalibrated.yaml")
        with open(os.path.join(cls.pkg, "test", "scenarios", "report_session.yaml")) as f:
            scenario = f.read()
        # The same session without the rate noise calibrates (the noise makes the K harmonics too uncertain).
        cls.scenarios = {"noisy": scenario, "quiet": re.sub(r"\n  rate_noise:[^\n]*", "", scenario)}
        cls.bags = {}
        for name, text in cls.scenarios.items():
            path = cls.path(name + ".yaml")
            with open(path, "w") as f:
                f.write(text)
            cls.bags[name] = cls.path(name + ".bag")
            code, _, err = run(HRG_BAG, "simulate", "--scenario", path, "--out", cls.bags[name])
            assert code == 0, err
        cls.spec = cls.path("spec.yaml")
        with open(cls.spec, "w") as f:
            f.write("name: test gyro\nmax_nonlinearity_ppm: 50\nmax_arw_deg_per_sqrt_h: 0.05\n")

    @classmethod
    def path(cls, name):
        return os.path.join(cls.work, name)

    def calibrate(self, name):
        params, report = self.path(name + ".params.yaml"), self.path(name + ".report.yaml")
        code, out, err = run(HRG_BAG, "calibrate", self.bags[name], "--params", self.prior, "--out", params,
                             "--report", report)
        return code, params, report, out + err

    def check_shown_numbers(self, page, report_path):
        """Every number the page shows with its data-q equals the report YAML's, to the digits shown."""
        with open(report_path) as f:
            report = yaml.load(f, Loader=self.models_module.Loader)
        checked = 0
        for q, shown in page.by_q.items():
            expected = lookup(report, q)
            if isinstance(expected, str):
                self.assertEqual(shown, expected, q)
            elif isinstance(expected, int) and not isinstance(expected, bool):
                self.assertEqual(int(shown), expected, q)
            else:
                digits = len(re.sub(r"[^0-9]", "", re.split(r"e", shown.lstrip("-"))[0]).lstrip("0")) or 1
                self.assertEqual(float(shown), float("%.*g" % (digits, expected)), "%s: page %s, YAML %r" %
                                 (q, shown, expected))
            checked += 1
        return report, checked

    def test_a_field_calibration_shows_the_gain_the_drift_and_that_k_was_kept(self):
        # A still gyro whose precession loop turned the wave both ways (config/scenarios/resonator_field.yaml).
        bag = self.path("field.bag")
        code, _, err = run(HRG_BAG, "simulate", "--scenario", os.path.join(self.pkg, "config", "scenarios",
                                                                            "resonator_field.yaml"), "--out", bag)
        self.assertEqual(code, 0, err)
        params, report_path = self.path("field.params.yaml"), self.path("field.report.yaml")
        code, out, err = run(HRG_BAG, "calibrate", bag, "--method", "field", "--params", self.prior, "--out", params,
                             "--report", report_path)
        self.assertEqual(code, 0, out + err)
        # The field method's stream is the precession loop's state, and the tool counts it as such.
        self.assertRegex(out, r"calibrate: precession states [1-9][0-9]*, dropped 0 ")
        self.assertNotIn("turntable records", out)
        html_path = self.path("field.html")
        code, stdout, err = run("/usr/bin/python3", self.script, report_path, "--out", html_path)
        self.assertEqual(code, 0, err)
        self.assertIn("ACCEPTED", stdout)
        code, page, err = render(html_path, self.work)
        self.assertEqual(code, 0, err[-2000:])
        console = [line for line in err.splitlines() if "CONSOLE" in line or "net::ERR" in line]
        self.assertEqual(console, [], "the page logged errors")
        self.assertEqual(page.body.get("data-images"), "2/2", "every figure decoded (D and the virtual rate's gain)")
        report, checked = self.check_shown_numbers(page, report_path)
        self.assertEqual(report["method"], "field")
        self.assertEqual(report["scale_factor"], [], "K is not estimated by a field calibration")
        gain, d = report["field"]["virtual_rate_gain"], report["drift"][0]
        # The gain's and D's every coefficient with its standard error, the field's own figures.
        for i in range(len(gain["orders"])):
            for key in ("cos", "cos_std", "sin", "sin_std"):
                self.assertIn("field.virtual_rate_gain.%s.%d" % (key, i), page.by_q)
        for i in range(len(d["orders"])):
            for key in ("cos", "cos_std", "sin", "sin_std"):
                self.assertIn("drift.0.%s.%d" % (key, i), page.by_q)
        for key in ("field.virtual_rate_gain.mean", "field.virtual_rate_gain.mean_std", "drift.0.mean",
                    "drift.0.mean_std", "field.k0_prior", "field.earth_rate", "field.positive_turns",
                    "field.negative_turns", "field.excess_scatter"):
            self.assertIn(key, page.by_q)
        self.assertIn("K was kept from the table calibration", page.by_id["k-kept"])
        with open(html_path) as f:
            html = f.read()
        self.assertIn("Precession states <span data-q=\"turntable_records\">", html)
        self.assertNotIn("Turntable records", html)
        self.assertNotIn("harmonics-scale_factor", page.by_id, "no K table: K was not estimated")
        # The page says the gain the simulated drive realised (1 + virtual_rate_gain_error = 1.003, within
        # the loop's theta-dependent part) and the prior's K0 it kept.
        self.assertAlmostEqual(float(page.by_q["field.virtual_rate_gain.mean"]), 1.003, delta=1e-3)
        with open(params) as f:
            written = f.read()
        with open(self.prior) as f:
            prior = yaml.safe_load(f)
        self.assertEqual(yaml.safe_load(written)["scale_factor"], prior["scale_factor"], "K kept from the prior")
        print("report test: field page, %d numbers checked; G_v0 %s +- %s" %
              (checked, page.by_q["field.virtual_rate_gain.mean"], page.by_q["field.virtual_rate_gain.mean_std"]))

    def test_a_refused_field_calibration_is_drawn_with_its_gate(self):
        # The wave precessed one way only: refused by the directions gate before any fit, so the report
        # has no field section; the page still draws, REFUSED, naming the gate.
        scenario = self.path("field_one_way.yaml")
        with open(os.path.join(self.pkg, "config", "scenarios", "resonator_field.yaml")) as f:
            text = f.read()
        self.assertEqual(text.count("rate: -0.2}"), 2)
        with open(scenario, "w") as f:
            f.write(text.replace("rate: -0.2}", "rate: 0.2}"))
        bag = self.path("field_one_way.bag")
        code, _, err = run(HRG_BAG, "simulate", "--scenario", scenario, "--out", bag)
        self.assertEqual(code, 0, err)
        params, report_path = self.path("field_one_way.params.yaml"), self.path("field_one_way.report.yaml")
        code, out, err = run(HRG_BAG, "calibrate", bag, "--method", "field", "--params", self.prior, "--out", params,
                             "--report", report_path)
        self.assertEqual(code, 1, out + err)
        self.assertFalse(os.path.exists(params))
        with open(report_path) as f:
            report = yaml.safe_load(f)
        self.assertNotIn("field", report)
        self.assertEqual([g["name"] for g in report["gates"] if not g["passed"]], ["directions"])
        html_path = self.path("field_one_way.html")
        code, stdout, err = run("/usr/bin/python3", self.script, report_path, "--out", html_path)
        self.assertEqual(code, 0, err)
        self.assertIn("REFUSED", stdout)
        with open(html_path) as f:
            page = f.read()
        self.assertIn("found only positive rates", page)

    def test_the_page_shows_the_numbers_of_the_calibration_report(self):
        code, params, report_path, log = self.calibrate("quiet")
        self.assertEqual(code, 0, log)
        verification = self.path("verification.yaml")
        with open(verification, "w") as f:
            f.write("before_ppm: 3425.0671\nafter_ppm: 0.5404\nafter_sigma_ppm: 0.1\n")
        out = self.path("quiet.html")
        code, stdout, err = run("/usr/bin/python3", self.script, report_path, "--bag", self.bags["quiet"], "--params",
                                params, "--spec", self.spec, "--verification", verification, "--out", out)
        self.assertEqual(code, 0, err)
        self.assertIn("ACCEPTED", stdout)
        with open(out) as f:
            text = f.read()
        outside_figures = re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", text)
        self.assertIsNone(re.search(r"(https?:|//[a-z]|ftp:|url\()", outside_figures), "the page must open offline")
        code, page, err = render(out, self.work)
        self.assertEqual(code, 0, err[-2000:])
        console = [line for line in err.splitlines() if "CONSOLE" in line or "net::ERR" in line]
        self.assertEqual(console, [], "the page logged errors")
        self.assertEqual(page.body.get("data-images"), "4/4", "every figure decoded (profile, K, D, Allan)")
        self.assertTrue(all(link.startswith("data:image/png;base64,") for link in page.links), page.links[:3])

        report, checked = self.check_shown_numbers(page, report_path)
        # Every harmonic coefficient and its standard error, every gate, every plateau, the diagnosis.
        k = report["scale_factor"][0]
        self.assertGreaterEqual(checked, 4 * len(k["orders"]) * 2 + 2 * len(report["gates"]) + 6 * len(
            report["plateaus"]), sorted(page.by_q))
        for key in ("scale_factor.0.cos_std.0", "drift.0.sin.0", "gates.8.value", "diagnosis.0.recommended_p.3",
                    "nonlinearity_ppm", "bias_trend.coefficients.0", "bias_trend.k0_inflation", "table_clock.offset",
                    "table_clock.jitter"):
            self.assertIn(key, page.by_q)
        self.assertEqual(page.by_id["verification-before"], "3425.067")
        self.assertEqual(page.by_id["verification-after"], "0.540")
        self.assertEqual(float(page.by_id["after-rms"]),
                         float("%.4g" % (1e6 * k["residual_rms"] / abs(k["mean"]))))
        self.assertEqual(page.by_id["calibration-status"], "ACCEPTED")
        self.assertEqual(page.by_id["overall"], "PASS")

        # It prints: a PDF of several A4 pages.
        pdf = self.path("quiet.pdf")
        code, _, err = run("chromium", "--headless", "--disable-gpu", "--no-sandbox", "--no-pdf-header-footer",
                           "--print-to-pdf=" + pdf, "file://" + out, timeout=120)
        self.assertEqual(code, 0, err[-2000:])
        with open(pdf, "rb") as f:
            data = f.read()
        pages = len(re.findall(rb"/Type\s*/Page[^s]", data))
        self.assertGreaterEqual(pages, 3)
        boxes = re.findall(rb"/MediaBox \[0 0 ([0-9.]+) ([0-9.]+)\]", data)
        self.assertEqual(len(boxes), pages)
        for w, h in boxes:
            self.assertTrue(abs(float(w) - 595.3) < 1.0 and abs(float(h) - 841.9) < 1.0, "A4 is 595 x 842 pt, not %s x %s"
                            % (w.decode(), h.decode()))
        self.assertTrue(data.startswith(b"%PDF"), "not a PDF")

    def test_the_allan_readings_find_the_simulated_angle_random_walk(self):
        code, params, report_path, log = self.calibrate("noisy")
        self.assertIn(code, (0, 1), log)  # the noise may make a gate refuse; the report is written either way
        out = self.path("noisy.html")
        code, stdout, err = run("/usr/bin/python3", self.script, report_path, "--bag", self.bags["noisy"], "--params",
                                self.prior, "--spec", self.spec, "--out", out)
        self.assertEqual(code, 0, err)
        code, page, err = render(out, self.work)
        self.assertEqual(code, 0, err[-2000:])
        arw = float(page.by_id["allan-angle_random_walk"])
        print("report test: ARW read %.5g rad/sqrt(s), simulated %.5g (%.2f %%)" % (arw, ARW, 100 * (arw / ARW - 1)))
        self.assertAlmostEqual(arw, ARW, delta=0.05 * ARW)
        # 200 s at rest cannot show a bias instability or a rate random walk: bounded, not read.
        self.assertTrue(page.by_id["allan-rate_random_walk"].startswith("\u2264"), page.by_id["allan-rate_random_walk"])
        self.assertTrue(page.by_id["allan-bias_instability"].startswith("\u2264"))

    def test_the_alignment_page_shows_the_numbers_of_the_align_results(self):
        # test/scenarios/north_align.yaml with rests of 25 s: the static mode on the first 20 s (its first 5,
        # 10, 20 s alone), the indexed mode on both rests, and one refused by the latitude gate.
        with open(os.path.join(self.pkg, "test", "scenarios", "north_align.yaml")) as f:
            text = f.read()
        self.assertIn("dwell: 65.0", text)
        scenario, bag = self.path("north_short.yaml"), self.path("north_short.bag")
        with open(scenario, "w") as f:
            f.write(text.replace("dwell: 65.0", "dwell: 25.0"))
        code, _, err = run(HRG_BAG, "simulate", "--scenario", scenario, "--out", bag, "--no-truth")
        self.assertEqual(code, 0, err)
        chain = ["--triad", os.path.join(self.pkg, "config", "triad.yaml")]
        for axis in "xyz":
            chain += ["--axis-params", axis + "=" + os.path.join(self.pkg, "test", "scenarios", "north_align_axis.yaml")]
        # The gyrocompass claims no precision nobody measured: each noise term and the level's sigmas given
        # (the simulated gyros' noise is white only, their model exact, the platter exactly level).
        level = ("level: {source: declared, roll_sigma: 0.0, pitch_sigma: 0.0}  # the body on the platter is level\n"
                 "noise: {residual_bias: 1.0e-8, angle_random_walk: 0.0, rate_random_walk: 0.0,"
                 " residual_drift_harmonics: 0.0}\n")
        settings = {"static": "mode: static  # the triad at rest\nlatitude: 0.9  # rad\n" + level,
                    "indexed": "mode: indexed  # two positions\nlatitude: 0.9  # rad\n" + level,
                    "refused": "mode: static  # the triad at rest\nlatitude: 0.9  # rad\nmax_latitude: 0.5  # rad\n" +
                    level}
        results, codes = [], {"static": 0, "indexed": 0, "refused": 1}
        for name, extra in (("static", ["--duration", "20", "--windows", "5,10,20"]), ("indexed", ["--duration", "56"]),
                            ("refused", [])):
            path, result = self.path(name + ".settings.yaml"), self.path(name + ".alignment.yaml")
            with open(path, "w") as f:
                f.write(settings[name])
            code, out, err = run(HRG_BAG, "align", bag, "--settings", path, "--output", result, *(chain + extra))
            self.assertEqual(code, codes[name], out + err)
            results.append(result)
        out = self.path("alignment.html")
        code, stdout, err = run(HRG_BAG, "report", *results, "--out", out)
        self.assertEqual(code, 0, err)
        self.assertIn("static.alignment.yaml ACCEPTED", stdout)
        self.assertIn("refused.alignment.yaml REFUSED (latitude)", stdout)
        code, page, err = render(out, self.work)
        self.assertEqual(code, 0, err[-2000:])
        console = [line for line in err.splitlines() if "CONSOLE" in line or "net::ERR" in line]
        self.assertEqual(console, [], "the page logged errors")
        # Per result the heading against window length; the residuals per segment of the two accepted.
        self.assertEqual(page.body.get("data-images"), "5/5")
        loaded = []
        for path in results:
            with open(path) as f:
                loaded.append(yaml.load(f, Loader=self.models_module.Loader))
        checked = 0
        for q, shown in page.by_q.items():
            index, where = q.split(":", 1)
            expected = lookup(loaded[int(index)], where)
            if isinstance(expected, str):
                self.assertEqual(shown, expected, q)
            elif isinstance(expected, int) and not isinstance(expected, bool):
                self.assertEqual(int(shown), expected, q)
            elif math.isnan(expected):  # a refused result's budget terms
                self.assertEqual(shown, "nan", q)
            else:
                expected = expected * page.scale.get(q, 1.0)
                digits = len(re.sub(r"[^0-9]", "", re.split(r"e", shown.lstrip("-"))[0]).lstrip("0")) or 1
                self.assertEqual(float(shown), float("%.*g" % (digits, expected)), "%s: page %s, YAML %r" %
                                 (q, shown, expected))
            checked += 1
        for key in ("0:heading_deg", "0:heading_sigma_deg", "0:budget_rad.total", "0:budget_rad.white_angle_noise",
                    "0:windows.0.heading_sigma_deg", "0:windows.2.heading_deg", "1:heading_deg",
                    "1:segments.1.residual_rate_rad_s.2", "1:segments.0.predicted_rms_rad.0", "2:gate"):
            self.assertIn(key, page.by_q)
        self.assertEqual(page.by_q["2:gate"], "latitude")
        self.assertEqual([page.by_id["status-%d" % i] for i in range(3)], ["ACCEPTED", "ACCEPTED", "REFUSED"])
        print("report test: alignment page, %d numbers checked; static %s +- %s deg, indexed %s +- %s deg" %
              (checked, page.by_q["0:heading_deg"], page.by_q["0:heading_sigma_deg"], page.by_q["1:heading_deg"],
               page.by_q["1:heading_sigma_deg"]))
        # An alignment result and a calibration report do not share a page.
        code, _, err = run(HRG_BAG, "report", results[0], self.prior, "--out", self.path("mix.html"))
        self.assertEqual(code, 2, err)
        self.assertIn("an alignment result and a calibration report do not share a page", err)
        # A damaged result is refused naming the key, nothing written.
        with open(results[0]) as f:
            good = f.read()
        for bad, message in ((re.sub(r"\nheading_deg: [^\n]*", "\nheading_deg: abc", good), "heading_deg: must be a number"),
                             (good.replace("{window_s: 5, ", "{"), "windows[0].window_s: missing"),
                             (re.sub(r"\n  total: [^\n]*", "", good), "budget_rad.total: missing")):
            path = self.path("damaged.alignment.yaml")
            with open(path, "w") as f:
                f.write(bad)
            code, _, err = run(HRG_BAG, "report", path, "--out", self.path("damaged.html"))
            self.assertEqual(code, 2, err)
            self.assertIn(message, err)
            self.assertFalse(os.path.exists(self.path("damaged.html")))
        self.assertFalse(os.path.exists(self.path("mix.html")))

    def test_hrg_bag_runs_the_scripts_with_their_own_help(self):
        for command, script in (("report", "hrg_report.py"), ("batch", "hrg_batch.py")):
            code, stdout, err = run(HRG_BAG, command, "--help")
            self.assertEqual(code, 0, err)
            self.assertIn("usage: " + script, stdout)
        code, _, err = run(HRG_BAG, "report", self.path("missing.report.yaml"), "--out", self.path("m.html"))
        self.assertEqual(code, 2, err)
        self.assertIn("no such file", err)

    def test_a_bad_specification_is_refused_with_its_key(self):
        code, params, report_path, log = self.calibrate("quiet")
        self.assertEqual(code, 0, log)
        for text, key in (("max_nonlinearity_ppm: 5\nmax_arw: 0.1\n", "'max_arw'"),
                          ("max_nonlinearity_ppm: fast\n", "'max_nonlinearity_ppm'"),
                          ("max_bias_instability_deg_per_h: -1\n", "'max_bias_instability_deg_per_h'"),
                          ("max_nonlinearity_ppm: 1%s\n" % ("0" * 400), "'max_nonlinearity_ppm'"),
                          ("name: [a, b]\n", "'name' must be text"),
                          ("- 1\n", "not a YAML map")):
            spec = self.path("bad_spec.yaml")
            with open(spec, "w") as f:
                f.write(text)
            out = self.path("bad.html")
            code, _, err = run("/usr/bin/python3", self.script, report_path, "--spec", spec, "--out", out)
            self.assertEqual(code, 2, err)
            self.assertIn(key, err)
            self.assertNotIn("Traceback", err)
            self.assertFalse(os.path.exists(out))
        code, _, err = run("/usr/bin/python3", self.script, self.bags["quiet"], "--out", self.path("bad.html"))
        self.assertEqual(code, 2, err)
        self.assertNotIn("Traceback", err)

    # ---- hrg_report: files ----

    def fresh(self, name):
        """An empty folder of this test's own under the work folder."""
        path = self.path(name)
        shutil.rmtree(path, ignore_errors=True)
        os.makedirs(path)
        return path

    def calibrated(self, folder):
        """A copy of the quiet session's accepted calibration (report, parameters) in `folder`."""
        if not hasattr(ReportTest, "_quiet"):
            code, params, report_path, log = self.calibrate("quiet")
            self.assertEqual(code, 0, log)
            ReportTest._quiet = (params, report_path)
        copies = []
        for source, name in zip(ReportTest._quiet, ("params.yaml", "report.yaml")):
            shutil.copyfile(source, os.path.join(folder, name))
            copies.append(os.path.join(folder, name))
        return copies

    def report(self, *args, **kwargs):
        return run("/usr/bin/python3", self.script, *args, **kwargs)

    def test_an_output_that_is_an_input_is_refused_by_file_identity(self):
        d = self.fresh("same_file")
        params, report = self.calibrated(d)
        os.link(self.bags["quiet"], os.path.join(d, "session.bag"))  # a name of the bag inside d
        spec, verification = os.path.join(d, "spec.yaml"), os.path.join(d, "verification.yaml")
        shutil.copyfile(self.spec, spec)
        with open(verification, "w") as f:
            f.write("before_ppm: 3425.0\nafter_ppm: 0.5\n")
        os.chmod(report, 0o640)
        os.makedirs(os.path.join(d, "sub"))
        inputs = ["report.yaml", "--bag", "session.bag", "--params", "params.yaml", "--spec", "spec.yaml",
                  "--verification", "verification.yaml"]
        cases = []
        for name in ("report.yaml", "session.bag", "params.yaml", "spec.yaml", "verification.yaml"):
            os.symlink(name, os.path.join(d, "link_to_" + name))
            os.link(os.path.join(d, name), os.path.join(d, "hard_" + name))
            cases += [(name, name), ("./" + name, name), ("sub/../" + name, name), (os.path.join(d, name), name),
                      ("link_to_" + name, name), ("hard_" + name, name)]
        before = snapshot(d)
        for out, name in cases:
            code, _, err = self.report(*inputs, "--out", out, cwd=d)
            self.assertEqual(code, 2, "%s -> %d: %s" % (out, code, err))
            self.assertIn("output '%s' is the same file as input '%s'" % (out, name), err)
            self.assertNotIn("Traceback", err)
            self.assertEqual(snapshot(d), before, "--out %s: every input as it was, no temporary" % out)

    def test_an_output_that_is_not_a_regular_file_is_refused_without_opening_it(self):
        d = self.fresh("not_regular")
        _, report = self.calibrated(d)
        os.mkfifo(os.path.join(d, "fifo.html"))
        os.makedirs(os.path.join(d, "folder.html"))
        outs = {"fifo.html": "a FIFO (named pipe)", "folder.html": "a directory"}
        try:
            os.mknod(os.path.join(d, "null.html"), 0o666 | stat.S_IFCHR, os.makedev(1, 3))
            outs["null.html"] = "a character device"
        except OSError as e:  # mknod needs CAP_MKNOD: the FIFO and the directory are still checked
            print("report test: no device node (%s)" % e)
        before = snapshot(d)
        for out, kind in outs.items():
            for spelling in (out, "link_" + out):
                if spelling != out and not os.path.lexists(os.path.join(d, spelling)):
                    os.symlink(out, os.path.join(d, spelling))
                    before = snapshot(d)
                # Opening the FIFO for writing would block: the time limit turns that into an error.
                code, _, err = self.report("report.yaml", "--out", spelling, cwd=d, timeout=60)
                self.assertEqual(code, 2, "%s: %s" % (spelling, err))
                self.assertIn("output '%s' is %s, not a regular file" % (spelling, kind), err)
                self.assertEqual(snapshot(d), before, spelling)

    def test_a_link_at_the_output_is_followed_and_the_mode_kept(self):
        d = self.fresh("link_out")
        self.calibrated(d)
        os.makedirs(os.path.join(d, "pages"))
        target = os.path.join(d, "pages", "gyro.html")
        with open(target, "w") as f:
            f.write("the previous page\n")
        os.chmod(target, 0o640)
        inode = os.stat(target).st_ino
        os.symlink("pages/gyro.html", os.path.join(d, "gyro.html"))
        code, _, err = self.report("report.yaml", "--out", "gyro.html", cwd=d)
        self.assertEqual(code, 0, err)
        self.assertEqual(os.readlink(os.path.join(d, "gyro.html")), "pages/gyro.html", "the link stays a link")
        with open(target) as f:
            self.assertIn("calibration-status", f.read())
        st = os.stat(target)
        self.assertEqual(stat.S_IMODE(st.st_mode), 0o640)
        self.assertNotEqual(st.st_ino, inode, "replaced by a rename, not rewritten in place")
        self.assertEqual(temporaries(d), [])
        # A new page: 0644 narrowed by the umask, as the C++ writers create files.
        code, _, err = self.report("report.yaml", "--out", "new.html", cwd=d, preexec_fn=lambda: os.umask(0o027))
        self.assertEqual(code, 0, err)
        self.assertEqual(stat.S_IMODE(os.stat(os.path.join(d, "new.html")).st_mode), 0o640)

    def test_a_full_disk_fails_with_exit_3_and_leaves_no_temporary(self):
        d = self.fresh("full_disk_report")
        disk = os.path.join(d, "disk")
        os.makedirs(disk)
        self.calibrated(d)
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", disk], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True)
        if mount.returncode != 0:
            self.skipTest("cannot mount a 64 KiB tmpfs to fill (needs root): " + mount.stdout.strip())
        try:
            old = os.path.join(disk, "old.html")
            with open(old, "w") as f:
                f.write("the previous page\n")
            # Nothing free, then 24 KiB: the page (about 100 KiB of figures) fails in the middle.
            for leave in (0, 24 * 1024):
                filler = fill(disk, leave)
                before = snapshot(disk)
                for out in (old, os.path.join(disk, "new.html")):
                    code, _, err = self.report(os.path.join(d, "report.yaml"), "--out", out)
                    self.assertEqual(code, 3, "%s, %d bytes free: %s" % (out, leave, err))
                    self.assertIn("No space left on device", err)
                    self.assertIn(out, err)
                    self.assertNotIn("Traceback", err)
                    self.assertEqual(snapshot(disk), before, "the old page as it was, no temporary")
                os.remove(filler)
        finally:
            subprocess.run(["umount", disk])

    def test_the_writer_leaves_the_target_as_it_was_on_an_exception_or_an_interrupt(self):
        d = self.fresh("writer_failures")
        sys.path.insert(0, os.path.join(self.pkg, "scripts"))
        import hrg_output_file
        target = os.path.join(d, "page.html")
        with open(target, "w") as f:
            f.write("the previous page\n")
        before = snapshot(d)
        for error in (KeyboardInterrupt, ValueError, SystemExit):
            with self.assertRaises(error):
                with hrg_output_file.AtomicOutputFile(target) as f:
                    f.write("half of the new page")
                    self.assertTrue(os.path.isfile(f.temporary_path))
                    raise error()
            self.assertEqual(snapshot(d), before, "%s: the temporary removed, the page as it was" % error.__name__)
        hrg_output_file.write_file_atomically(target, "the new page\n")
        with open(target) as f:
            self.assertEqual(f.read(), "the new page\n")
        self.assertEqual(sorted(os.listdir(d)), ["page.html"])

    def test_temporaries_of_a_killed_writer_are_removed_by_the_python_and_the_cpp_writers(self):
        d = self.fresh("stale")
        self.calibrated(d)
        # A writer of the shared module killed in the middle of a page, and of a calibration report.
        child = ("import sys, time; sys.path.insert(0, %r); import hrg_output_file as h\n"
                 "files = [h.AtomicOutputFile(p) for p in sys.argv[1:]]\n"
                 "for f in files: f.write('half a file')\n"
                 "print(' '.join(f.temporary_path for f in files), flush=True); time.sleep(600)\n"
                 % os.path.join(self.pkg, "scripts"))
        page, cal_report = os.path.join(d, "page.html"), os.path.join(d, "cal.report.yaml")
        writer = subprocess.Popen(["/usr/bin/python3", "-c", child, page, cal_report], stdout=subprocess.PIPE,
                                  universal_newlines=True)
        left = writer.stdout.readline().split()
        writer.send_signal(signal.SIGKILL)
        writer.wait()
        writer.stdout.close()
        self.assertEqual(len(left), 2)
        for path, target in zip(left, (page, cal_report)):
            # The C++ naming: <target>.tmp.<pid>.XXXXXX, six letters or digits.
            self.assertRegex(path, r"^%s\.tmp\.%d\.[A-Za-z0-9]{6}$" % (re.escape(target), writer.pid))
            self.assertTrue(os.path.isfile(path))
        not_ours = os.path.join(d, "page.html.tmp.notours")
        with open(not_ours, "w") as f:
            f.write("someone else's\n")
        time.sleep(0.05)  # stale means older than the next write
        code, _, err = self.report(os.path.join(d, "report.yaml"), "--out", page)
        self.assertEqual(code, 0, err)
        self.assertFalse(os.path.exists(left[0]), "hrg_report removed the killed writer's temporary")
        self.assertTrue(os.path.exists(not_ours), "a name that is not a writer's temporary is never touched")
        code, _, err = run(HRG_BAG, "calibrate", self.bags["quiet"], "--params", self.prior, "--out",
                           os.path.join(d, "cal.yaml"), "--report", cal_report)
        self.assertEqual(code, 0, err)
        self.assertFalse(os.path.exists(left[1]), "the C++ writer removed the Python writer's temporary")

    # ---- hrg_report: malformed inputs ----

    def test_a_specification_without_a_name_is_accepted(self):
        d = self.fresh("spec_without_name")
        self.calibrated(d)
        with open(os.path.join(d, "spec.yaml"), "w") as f:
            f.write("max_nonlinearity_ppm: 50\nrequire_accepted: true\n")  # `name` is optional
        code, stdout, err = self.report("report.yaml", "--spec", "spec.yaml", "--out", "out.html", cwd=d)
        self.assertEqual(code, 0, err)
        self.assertIn("spec PASS", stdout)
        with open(os.path.join(d, "out.html")) as f:
            self.assertIn('<span id="overall" class="verdict pass">PASS</span>', f.read())

    def test_a_key_given_twice_is_refused_in_every_yaml_read(self):
        d = self.fresh("duplicates")
        _, report = self.calibrated(d)
        with open(report) as f:
            text = f.read()
        with open(os.path.join(d, "dup_report.yaml"), "w") as f:
            f.write(text.replace("\nmethod: ", "\nsamples: 3\nmethod: ", 1))
        with open(os.path.join(d, "spec.yaml"), "w") as f:
            f.write("name: gyro\nmax_nonlinearity_ppm: 5000\nmax_nonlinearity_ppm: 50\n")
        with open(os.path.join(d, "verification.yaml"), "w") as f:
            f.write("before_ppm: 3425.0\nafter_ppm: 0.5\nafter_ppm: 0.6\n")
        for args, key, path in ((["dup_report.yaml"], "samples", "dup_report.yaml"),
                                (["report.yaml", "--spec", "spec.yaml"], "max_nonlinearity_ppm", "spec.yaml"),
                                (["report.yaml", "--verification", "verification.yaml"], "after_ppm",
                                 "verification.yaml")):
            code, _, err = self.report(*args, "--out", "out.html", cwd=d)
            self.assertEqual(code, 2, err)
            self.assertIn("key '%s' given more than once" % key, err)
            self.assertIn(path, err)
            self.assertFalse(os.path.exists(os.path.join(d, "out.html")))

    def test_a_malformed_calibration_report_is_refused_naming_the_key(self):
        d = self.fresh("malformed")
        _, report = self.calibrated(d)
        with open(report) as f:
            good = f.read()
        k0 = re.search(r"\nscale_factor:\n  - orders: \[[^\]]*\]\n    mean: ([^\n]+)\n", good)
        self.assertIsNotNone(k0, good[:2000])

        def k0_is(text):
            return good[:k0.start(1)] + text + good[k0.end(1):]

        def without(key):
            return re.sub(r"\n%s:(\n  [^\n]*| [^\n]*)+" % key, "", good, count=1)

        huge = "x" * 5000000
        cases = [
            (k0_is("0"), "scale_factor[0].mean: must be a non-zero finite number, not 0"),
            (k0_is(".nan"), "scale_factor[0].mean: must be a non-zero finite number, not nan"),
            (k0_is("abc"), "scale_factor[0].mean: must be a non-zero finite number, not 'abc'"),
            (k0_is(huge), "scale_factor[0].mean: must be a non-zero finite number, not 'xxxx"),
            (good.replace("\naccepted: true\n", '\naccepted: "no"\n'), "accepted: must be true or false"),
            (good.replace("\naccepted: true\n", "\naccepted: 1\n"), "accepted: must be true or false"),
            (without("binned"), "binned: missing"),
            (without("turntable_rejected"), "turntable_rejected: missing"),
            (without("scale_factor"), "scale_factor: missing"),
            (good.replace("\nrestarts: 0\n", "\nrestarts: many\n"), "restarts: must be a whole number"),
            (re.sub(r"\n    cos: \[[^\]\n]*\]", "\n    cos: [1.0e-6]", good, count=1),
             "scale_factor[0].cos: must have 4 entries, as many as scale_factor[0].orders, not 1"),
            (re.sub(r"\ngates:\n  - \{name: ([a-z_]+), passed: true", r"\ngates:\n  - {name: \1, passed: yes!",
                    good, count=1), "gates[0].passed: must be true or false"),
            (good.replace("\nplateaus:\n", "\nplateaus: 3\nunused:\n", 1), "plateaus: must be a list"),
        ]
        for text, message in cases:
            self.assertNotEqual(text, good, message)
            with open(os.path.join(d, "bad.yaml"), "w") as f:
                f.write(text)
            code, _, err = self.report("bad.yaml", "--out", "out.html", cwd=d)
            self.assertEqual(code, 2, "%s: %s" % (message, err[:2000]))
            self.assertIn("calibration report bad.yaml: " + message, err)
            self.assertNotIn("Traceback", err)
            self.assertLess(len(err), 1000, "a long value is cut in the message")
            if huge in text:
                self.assertIn("(5000002 characters)", err, "the message says how long the value was")
            self.assertFalse(os.path.exists(os.path.join(d, "out.html")))

    def test_a_campaign_of_three_bags_one_broken(self):
        bags = self.path("campaign")
        os.makedirs(bags)
        for seed in (1, 2):
            scenario = self.path("seed%d.yaml" % seed)
            with open(scenario, "w") as f:
                f.write(re.sub(r"\nseed: 1 ", "\nseed: %d " % seed, self.scenarios["quiet"]))
            code, _, err = run(HRG_BAG, "simulate", "--scenario", scenario, "--out",
                               os.path.join(bags, "gyro%d.bag" % seed))
            self.assertEqual(code, 0, err)
        with open(self.bags["quiet"], "rb") as f, open(os.path.join(bags, "gyro0_broken.bag"), "wb") as g:
            g.write(f.read(5000))  # a copy cut short
        out = self.path("campaign_out")
        code, stdout, err = run("/usr/bin/python3", os.path.join(self.pkg, "scripts", "hrg_batch.py"), bags, out,
                                "--jobs", "2", "--params", self.prior, "--spec", self.spec)
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("2 of 3 passed", stdout)
        for name in ("gyro1", "gyro2"):
            for f in ("params.yaml", "report.yaml", "report.html", "log.txt"):
                self.assertTrue(os.path.isfile(os.path.join(out, name, f)), name + "/" + f)
        self.assertFalse(os.path.exists(os.path.join(out, "gyro0_broken", "params.yaml")))
        code, page, err = render(os.path.join(out, "index.html"), self.work)
        self.assertEqual(code, 0, err)
        self.assertEqual(page.by_id["summary"], "2 of 3 passed")
        with open(os.path.join(out, "index.html")) as f:
            index = f.read()
        rows = re.findall(r'<tr class="bag" data-name="([^"]+)">(.*?)</tr>', index, re.S)
        self.assertEqual([r[0] for r in rows], ["gyro0_broken", "gyro1", "gyro2"])
        self.assertIn("truncated", rows[0][1])
        self.assertIn(">FAIL<", rows[0][1])
        for name, row in rows[1:]:
            self.assertIn(">PASS<", row, name)
            self.assertIn('href="%s/report.html"' % name, row)
        # Every bag of the folder passing exits 0 (through hrg_bag, which runs the script beside itself).
        # The specification without its optional name (which used to fail every bag).
        os.remove(os.path.join(bags, "gyro0_broken.bag"))
        unnamed = self.path("spec_unnamed.yaml")
        with open(self.spec) as f, open(unnamed, "w") as g:
            g.write(re.sub(r"(?m)^name:.*\n", "", f.read()))
        code, stdout, err = run(HRG_BAG, "batch", bags, self.path("campaign_ok"), "--params", self.prior, "--spec",
                                unnamed)
        self.assertEqual(code, 0, stdout + err)
        self.assertIn("2 of 2 passed", stdout)
        self.assertEqual(temporaries(self.path("campaign_ok")), [])

    # ---- hrg_batch ----

    def batch(self, *args, **kwargs):
        return run("/usr/bin/python3", os.path.join(self.pkg, "scripts", "hrg_batch.py"), *args, **kwargs)

    def fake_hrg_bag(self, folder):
        """A stand-in for hrg_bag (HRG_BAG): `calibrate` of a bag named *slow* hangs with a child of its
        own (their pids in <bag>.pids); of any other bag it fails at once."""
        path = os.path.join(folder, "fake_hrg_bag")
        with open(path, "w") as f:
            f.write('#!/bin/sh\ncase "$2" in\n  *slow*) sleep 1000 & echo "$$ $!" > "$2.pids"; wait ;;\n'
                    '  *) echo "fake: cannot calibrate $2"; exit 2 ;;\nesac\n')
        os.chmod(path, 0o755)
        return dict(os.environ, HRG_BAG=path)

    @staticmethod
    def index_rows(out):
        with open(os.path.join(out, "index.html")) as f:
            return dict(re.findall(r'<tr class="bag" data-name="([^"]*)">(.*?)</tr>', f.read(), re.S))

    def test_batch_refuses_a_fifo_and_kills_a_bag_at_its_time_limit(self):
        d = self.fresh("batch_limits")
        env = self.fake_hrg_bag(d)
        bags, out = os.path.join(d, "bags"), os.path.join(d, "out")
        os.makedirs(os.path.join(bags, "folder.bag"))
        os.mkfifo(os.path.join(bags, "fifo.bag"))  # opening it to read would block the campaign for ever
        for name in ("a_slow.bag", "b.bag"):
            open(os.path.join(bags, name), "w").close()
        start = time.monotonic()
        code, stdout, err = self.batch(bags, out, "--timeout", "3", "--jobs", "2", env=env, timeout=120)
        self.assertLess(time.monotonic() - start, 60)
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("0 of 4 passed", stdout)
        rows = self.index_rows(out)
        self.assertEqual(sorted(rows), ["a_slow", "b", "fifo", "folder"])
        self.assertIn("not a regular file: it is a FIFO (named pipe)", rows["fifo"])
        self.assertIn("not a regular file: it is a directory", rows["folder"])
        self.assertIn("timed out after 3 s", rows["a_slow"])
        self.assertIn("fake: cannot calibrate", rows["b"], "the other bags go on")
        self.assertTrue(stat.S_ISFIFO(os.stat(os.path.join(bags, "fifo.bag")).st_mode))
        with open(os.path.join(out, "a_slow", "log.txt")) as f:
            self.assertIn("timed out after 3 s: killed", f.read())
        with open(os.path.join(bags, "a_slow.bag.pids")) as f:
            pids = [int(p) for p in f.read().split()]
        for pid in pids:  # the bag's whole process group: a zombie no one reaps is dead too
            try:
                with open("/proc/%d/status" % pid) as f:
                    self.assertIn("State:\tZ", f.read(), "process %d of the timed-out bag still runs" % pid)
            except FileNotFoundError:
                pass
        self.assertEqual(temporaries(out), [])

    def test_batch_writes_the_index_whatever_the_bags_are_named_and_when_every_bag_fails(self):
        d = self.fresh("batch_names")
        env = self.fake_hrg_bag(d)
        bags, out = os.path.join(d, "bags"), os.path.join(d, "out")
        os.makedirs(bags)
        # index.html.bag used to make the folder index.html/, which blocked the index; ".bag" and
        # "...bag" would make the folders "" (OUT_DIR itself) and "..".
        for name in ("index.html.bag", "index.html_2.bag", ".bag", "...bag"):
            open(os.path.join(bags, name), "w").close()
        code, stdout, err = self.batch(bags, out, env=env)
        self.assertEqual(code, 1, stdout + err)
        self.assertIn("0 of 4 passed", stdout)
        self.assertTrue(stat.S_ISREG(os.stat(os.path.join(out, "index.html")).st_mode))
        rows = self.index_rows(out)
        for name, folder in (("index.html", "index.html_3"), ("index.html_2", "index.html_2"), ("", "_2"),
                             ("..", ".._2")):
            self.assertIn('href="%s/log.txt"' % folder, rows[name], name)
            self.assertTrue(os.path.isfile(os.path.join(out, folder, "log.txt")), folder)
        self.assertEqual(sorted(os.listdir(d)), ["bags", "fake_hrg_bag", "out"], "nothing written beside OUT_DIR")
        self.assertFalse(os.path.exists(os.path.join(out, "log.txt")))

    def test_batch_exit_codes_for_folders_it_cannot_use(self):
        d = self.fresh("batch_folders")
        env = self.fake_hrg_bag(d)
        bags = os.path.join(d, "bags")
        os.makedirs(bags)
        open(os.path.join(bags, "b.bag"), "w").close()
        open(os.path.join(d, "a_file"), "w").close()
        for out, message in ((os.path.join(d, "a_file", "out"), "cannot create the output folder"),
                             (os.path.join(d, "a_file"), "it exists and is not a folder")):
            code, stdout, err = self.batch(bags, out, env=env)
            self.assertEqual(code, 3, stdout + err)
            self.assertIn(message, err)
            self.assertNotIn("Traceback", err)
        code, _, err = self.batch(os.path.join(d, "missing"), os.path.join(d, "out"), env=env)
        self.assertEqual(code, 2, err)
        self.assertIn("is not a folder", err)
        readonly = os.path.join(d, "readonly")
        os.makedirs(readonly)
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", readonly],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        if mount.returncode == 0:
            try:
                for out in (readonly, os.path.join(readonly, "out")):
                    code, stdout, err = self.batch(bags, out, env=env)
                    self.assertEqual(code, 3, stdout + err)
                    self.assertIn("Read-only file system", err)
                    self.assertNotIn("Traceback", err)
            finally:
                subprocess.run(["umount", readonly])
        else:
            print("report test: no read-only tmpfs (%s)" % mount.stdout.strip())
        if os.geteuid() != 0:
            return
        # A bag folder the user may not list (root lists everything: run as nobody). Nobody must reach
        # the script and the work folder: a checkout inside a private folder (mktemp -d) keeps it out.
        def reachable_by_others(path, mode):
            path = os.path.realpath(path)
            parents = [os.path.dirname(path)]
            while parents[-1] != os.path.dirname(parents[-1]):
                parents.append(os.path.dirname(parents[-1]))
            return os.stat(path).st_mode & mode and all(os.stat(p).st_mode & 0o001 for p in parents)
        if not (reachable_by_others(os.path.join(self.pkg, "scripts", "hrg_batch.py"), 0o004) and reachable_by_others(d, 0o001)):
            print("report test: the checkout or the work folder is private to its owner; the unlistable "
                  "bag folder is not tried as nobody")
            return
        private = os.path.join(d, "private")
        os.makedirs(private, mode=0o700)
        mpl = os.path.join(d, "mpl")
        os.makedirs(mpl)
        os.chmod(mpl, 0o777)

        def as_nobody():
            os.setgroups([])
            os.setgid(65534)
            os.setuid(65534)
        code, stdout, err = self.batch(private, os.path.join(d, "out"), env=dict(env, MPLCONFIGDIR=mpl),
                                       preexec_fn=as_nobody)
        self.assertEqual(code, 2, stdout + err)
        self.assertIn("cannot list the bag folder %s: Permission denied" % private, err)
        self.assertFalse(os.path.exists(os.path.join(d, "out")))

    def test_batch_outputs_are_never_its_inputs(self):
        d = self.fresh("batch_same_file")
        env = self.fake_hrg_bag(d)
        bags, out = os.path.join(d, "bags"), os.path.join(d, "out")
        os.makedirs(bags)
        open(os.path.join(bags, "b.bag"), "w").close()
        os.makedirs(os.path.join(out, "b"))
        shutil.copyfile(self.prior, os.path.join(out, "b", "params.yaml"))  # last campaign's, as the prior
        with open(os.path.join(out, "index.html"), "w") as f:
            f.write("max_nonlinearity_ppm: 50\n")  # a specification where the index goes
        with open(os.path.join(out, "b", "log.txt"), "w") as f:
            f.write("{}\n")
        os.symlink("out/b/params.yaml", os.path.join(d, "prior_link.yaml"))
        before = snapshot(d)
        for option, path, output in (("--params", os.path.join(out, "b", "params.yaml"), "b/params.yaml"),
                                     ("--params", os.path.join(d, "prior_link.yaml"), "b/params.yaml"),
                                     ("--spec", os.path.join(out, "index.html"), "index.html"),
                                     ("--config", os.path.join(out, "b", "log.txt"), "b/log.txt")):
            code, stdout, err = self.batch(bags, out, option, path, env=env)
            self.assertEqual(code, 2, stdout + err)
            self.assertIn("refused: output '%s' is the same file as input '%s'" % (os.path.join(out, output), path),
                          err)
            self.assertEqual(snapshot(d), before, "%s %s: nothing written" % (option, path))

    def test_batch_on_a_full_disk_exits_3_and_leaves_no_temporary(self):
        d = self.fresh("batch_full_disk")
        bags, disk = os.path.join(d, "bags"), os.path.join(d, "disk")
        os.makedirs(bags)
        os.makedirs(disk)
        os.link(self.bags["quiet"], os.path.join(bags, "gyro.bag"))
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", disk], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True)
        if mount.returncode != 0:
            self.skipTest("cannot mount a 64 KiB tmpfs to fill (needs root): " + mount.stdout.strip())
        try:
            out = os.path.join(disk, "out")
            os.makedirs(os.path.join(out, "gyro"))
            for name in ("index.html", "gyro/log.txt"):
                with open(os.path.join(out, name), "w") as f:
                    f.write("the previous campaign\n")
            filler = fill(disk, 0)
            before = snapshot(out)
            code, stdout, err = self.batch(bags, out, "--params", self.prior)
            self.assertEqual(code, 3, stdout + err)
            self.assertIn("the index was not written", err)
            self.assertIn("No space left on device", err)
            self.assertNotIn("Traceback", err)
            self.assertEqual(snapshot(out), before, "the previous index and log as they were, no temporary")
            os.remove(filler)
        finally:
            subprocess.run(["umount", disk])


if __name__ == "__main__":
    rospy.init_node("report_test")
    rostest.rosrun("hrg_gyro", "report", ReportTest)
