#!/usr/bin/env python3
"""The HTML calibration report and the batch campaign, looked at as a person would: the page is
rendered by headless Chromium, must load with no console error and every figure decoded, and the
numbers the browser shows must equal those of the calibration report YAML. The Allan readings are
checked against a simulated gyro whose angle random walk is known. Needs no master; run as a rostest
for the package environment."""
import html.parser
import os
import re
import shutil
import subprocess
import sys
import unittest

import rospy
import rostest
import yaml

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()
ARW = 1.0e-4  # rad/sqrt(s), resonator.rate_noise of test/scenarios/report_session.yaml


def run(*args, timeout=600):
    p = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                       timeout=timeout)
    return p.returncode, p.stdout, p.stderr


class Page(html.parser.HTMLParser):
    """The rendered DOM: text of every element carrying data-q or id, and the body's attributes."""

    def __init__(self):
        super().__init__()
        self.stack, self.by_q, self.by_id, self.body, self.links = [], {}, {}, {}, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "body":
            self.body = a
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
        cls.report_module = __import__("hrg_report")  # its YAML loader reads 1e-05 as yaml-cpp means it
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

        with open(report_path) as f:
            report = yaml.load(f, Loader=self.report_module.Loader)
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
        # Every harmonic coefficient and its standard error, every gate, every plateau, the diagnosis.
        k = report["scale_factor"][0]
        self.assertGreaterEqual(checked, 4 * len(k["orders"]) * 2 + 2 * len(report["gates"]) + 6 * len(
            report["plateaus"]), sorted(page.by_q))
        for key in ("scale_factor.0.cos_std.0", "drift.0.sin.0", "gates.8.value", "diagnosis.0.recommended_p.3",
                    "nonlinearity_ppm"):
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
        os.remove(os.path.join(bags, "gyro0_broken.bag"))
        code, stdout, err = run(HRG_BAG, "batch", bags, self.path("campaign_ok"), "--params", self.prior, "--spec",
                                self.spec)
        self.assertEqual(code, 0, stdout + err)
        self.assertIn("2 of 2 passed", stdout)


if __name__ == "__main__":
    rospy.init_node("report_test")
    rostest.rosrun("hrg_gyro", "report", ReportTest)
