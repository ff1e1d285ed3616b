#!/usr/bin/env python3
"""Soak test (`make soak`): a long simulated session at 10 kHz through driver_sim, processor and
calibrator, with the resident memory of the nodes sampled and every diagnostic watched.

Environment: SOAK_SECONDS (default 3600), SOAK_MODE (nodelets | processes, default nodelets),
SOAK_RATE (channel rate in Hz, default 10000), SOAK_OUT (default bench_output/soak).
Writes SOAK_OUT/soak.yaml, soak.md, rss.csv (RSS and hypervisor steal), heap.csv (live heap) and
stamp_delay.csv; exits non-zero when the session lost samples, a
diagnostic went to ERROR after the start-up, or memory grew (more than SOAK_RSS_GROWTH_MIB, default
2 MiB, between the end of the first tenth and the end).
"""
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

import yaml

import proc_stats

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def log(msg):
    print("soak: " + msg, file=sys.stderr, flush=True)


def driver_lateness(out, t0):
    """[(t since t0, seconds behind)] from driver_sim's "behind schedule" warnings in this run's
    rosout.log (found through the log directory roslaunch names in its output)."""
    try:
        with open(os.path.join(out, "roslaunch.log")) as f:
            head = f.read(4000)
        logdir = os.path.dirname(re.search(r"logging to (\S+)", head).group(1))
        with open(os.path.join(logdir, "rosout.log")) as f:
            lines = f.readlines()
    except (IOError, OSError, AttributeError):
        return []
    found = []
    for line in lines:
        m = re.match(r"(\d+\.\d+) WARN .*driver_sim: ([0-9.]+) s behind schedule", line)
        if m:
            found.append((float(m.group(1)) - t0, float(m.group(2))))
    return found


def scenario(seconds, rate):
    """The live benchmark's gyro on a dual-rate profile that fills the soak (226 s per pair)."""
    with open(os.path.join(ROOT, "bench", "live_scenario.yaml")) as f:
        s = yaml.safe_load(f)
    frequency = 10000.0 if rate > 5000 else 5000.0
    s["resonator"]["frequency"] = frequency
    s["resonator"]["periods_per_output"] = max(1, int(round(frequency / rate)))
    # One repeat is a pair of 226 s plateaus (452 s); end with a rest long enough for the calibrator
    # to finish (auto_finish_idle 20 s) inside the soak.
    repeat = max(1, int((seconds - 10.0 - 60.0) // 452.0))
    s["turntable"]["profile"] = [
        {"type": "dwell", "duration": 10.0, "label": "start"},
        {"type": "dual_rate", "rates": [0.05, -0.05], "duration": 226.0, "settle": 3.0, "repeat": repeat,
         "label": "calibration"},
        {"type": "dwell", "duration": max(60.0, seconds - 10.0 - 452.0 * repeat), "label": "rest"},
    ]
    return s, frequency / s["resonator"]["periods_per_output"]


def main():
    seconds = float(os.environ.get("SOAK_SECONDS", "3600"))
    mode = os.environ.get("SOAK_MODE", "nodelets")
    rate = float(os.environ.get("SOAK_RATE", "10000"))
    growth_limit = float(os.environ.get("SOAK_RSS_GROWTH_MIB", "2.0"))
    out = os.environ.get("SOAK_OUT", os.path.join(ROOT, "bench_output", "soak"))
    os.makedirs(out, exist_ok=True)
    scen, output_rate = scenario(seconds, rate)
    scen_file = os.path.join(out, "scenario.yaml")
    with open(scen_file, "w") as f:
        yaml.safe_dump(scen, f)
    params = os.path.join(out, "params.yaml")
    shutil.copy(os.path.join(ROOT, "config", "params_uncalibrated.yaml"), params)

    port = random.randint(20000, 40000)
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
    log("%.0f s at %.0f Hz as %s; output in %s" % (seconds, output_rate, mode, out))
    launch = subprocess.Popen(["roslaunch", "-p", str(port), os.path.join(ROOT, "bench", "soak.launch"),
                               "scenario:=" + scen_file, "parameter_file:=" + params,
                               "use_nodelets:=%s" % str(mode == "nodelets").lower(),
                               "output_rate:=%s" % output_rate],
                              env=env, stdout=open(os.path.join(out, "roslaunch.log"), "w"),
                              stderr=subprocess.STDOUT, preexec_fn=os.setsid)
    patterns = ({"manager": "__name:=gyro_manager"} if mode == "nodelets" else
                {"driver_sim": "__name:=driver_sim", "processor": "__name:=processor",
                 "calibrator": "__name:=calibrator"})
    samples, steal = [], []  # steal: (t, % of the VM's CPU time the hypervisor took in the interval)
    state = {"errors": [], "levels": {}, "processor": {}, "results": [], "delays": [], "heap": []}
    try:
        time.sleep(5)
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
        from hrg_gyro.msg import CalibrationResult

        def on_diag(msg):
            for s in msg.status:
                state["levels"][s.name] = max(state["levels"].get(s.name, 0), ord(s.level) if isinstance(
                    s.level, bytes) else s.level)
                level = ord(s.level) if isinstance(s.level, bytes) else s.level
                if level >= DiagnosticStatus.ERROR and time.time() - state.get("t0", time.time()) > 15:
                    state["errors"].append((round(time.time() - state["t0"], 1), s.name, s.message))
                if s.name.endswith("processor: input") or s.name.endswith("processor: wave"):
                    state["processor"].update((kv.key, kv.value) for kv in s.values)
                if s.name.endswith("processor: memory"):
                    v = dict((kv.key, kv.value) for kv in s.values)
                    try:
                        state["heap"].append((time.time() - state.get("t0", time.time()),
                                              float(v["process heap in use (MiB)"])))
                    except (KeyError, ValueError):
                        pass
                if s.name.endswith("processor: channels stamps"):
                    # Latest delay of the window: how far behind its samples' stamps the processor ran.
                    # (diagnostic_updater versions name the values differently)
                    v = dict((kv.key.rstrip(":"), kv.value) for kv in s.values)
                    try:
                        if "Timestamp delay - Earliest | Latest | Acceptable" in v:
                            early, late = v["Timestamp delay - Earliest | Latest | Acceptable"].split("|")[:2]
                        else:
                            early, late = v["Earliest timestamp delay"], v["Latest timestamp delay"]
                        state["delays"].append((round(time.time() - state.get("t0", time.time()), 1),
                                                float(early), float(late)))
                    except (KeyError, ValueError):
                        pass

        def on_result(msg):
            state["results"].append({"accepted": msg.accepted, "written": msg.written, "reason": msg.reason,
                                     "nonlinearity_ppm": msg.nonlinearity_ppm, "duration_s": msg.duration,
                                     "samples": msg.samples, "coverage": msg.coverage})
            log("calibration result: accepted=%s written=%s %s" % (msg.accepted, msg.written, msg.reason))

        rospy.init_node("soak_monitor", anonymous=True, disable_signals=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=100)
        rospy.Subscriber("/calibrator/result", CalibrationResult, on_result, queue_size=10)
        t0 = state["t0"] = time.time()
        cpu_before = proc_stats.cpu_times()
        next_report = t0 + 60
        while time.time() - t0 < seconds and launch.poll() is None:
            time.sleep(10)
            now = proc_stats.scan(patterns)
            samples.append((time.time() - t0, now))
            cpu_now = proc_stats.cpu_times()
            steal.append((time.time() - t0, 100.0 * (cpu_now[1] - cpu_before[1]) / max(1, cpu_now[0] - cpu_before[0])))
            cpu_before = cpu_now
            if time.time() > next_report:
                next_report += 300
                log("%5.0f s: rss %s MiB; received %s, lost %s, errors %d" % (
                    time.time() - t0, ", ".join("%s %.1f" % (k, v[0]) for k, v in sorted(now.items())),
                    state["processor"].get("received"), state["processor"].get("lost (sequence gaps)"),
                    len(state["errors"])))
        time.sleep(3)  # last diagnostics
        rospy.signal_shutdown("done")
    finally:
        os.killpg(launch.pid, signal.SIGINT)
        try:
            launch.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(launch.pid, signal.SIGKILL)

    with open(os.path.join(out, "rss.csv"), "w") as f:
        names = sorted(patterns)
        f.write("t_s," + ",".join("%s_rss_mib" % n for n in names) + ",steal_percent\n")
        for (t, now), (_, st) in zip(samples, steal):
            f.write("%.1f,%s,%.1f\n" % (t, ",".join("%.2f" % now[n][0] if n in now else "" for n in names), st))
    report = {"seconds": seconds, "mode": mode, "output_rate_hz": output_rate, "nodes": {}}
    ok = True
    warm = [s for s in samples if s[0] >= 0.1 * seconds]
    for name in sorted(patterns):
        series = [(t, now[name]) for t, now in samples if name in now]
        if not series:
            ok = False
            report["nodes"][name] = "never seen"
            continue
        after_warmup = [v for t, v in series if t >= 0.1 * seconds] or [series[-1][1]]
        cpu = 100.0 * (series[-1][1][1] - series[0][1][1]) / proc_stats.CLK_TCK / max(series[-1][0] - series[0][0], 1e-9)
        node = {"rss_start_mib": round(series[0][1][0], 2), "rss_after_warmup_mib": round(after_warmup[0][0], 2),
                "rss_end_mib": round(series[-1][1][0], 2), "rss_max_mib": round(max(v[0] for _, v in series), 2),
                "growth_after_warmup_mib": round(series[-1][1][0] - after_warmup[0][0], 2),
                "cpu_percent": round(cpu, 1)}
        report["nodes"][name] = node
        if node["growth_after_warmup_mib"] > growth_limit:
            ok = False
    p = state["processor"]
    received = int(p.get("received", 0))
    lost = int(p.get("lost (sequence gaps)", -1))
    report["processor"] = {k: p.get(k) for k in ("received", "lost (sequence gaps)", "outputs", "rejected non-finite",
                                                 "rejected degenerate", "rejected jumps", "gaps not integrated")}
    report["expected_samples"] = int(round(output_rate * (samples[-1][0] if samples else 0)))
    with open(os.path.join(out, "heap.csv"), "w") as f:
        f.write("t_s,heap_in_use_mib\n")
        f.writelines("%.1f,%.3f\n" % h for h in state["heap"])
    heap_warm = [h for t, h in state["heap"] if t >= 0.1 * seconds]
    if heap_warm:
        # Live malloc bytes of the process holding the processor (the whole manager for nodelets):
        # what a leak would raise, whatever the allocator keeps resident.
        report["heap_in_use_mib"] = {"after_warmup": round(heap_warm[0], 2), "end": round(heap_warm[-1], 2),
                                     "max": round(max(heap_warm), 2),
                                     "growth_after_warmup": round(heap_warm[-1] - heap_warm[0], 2)}
    lags = sorted(max(abs(e), abs(l)) for _, e, l in state["delays"])
    if lags:
        report["stamp_delay_s"] = {"windows": len(lags), "median": round(lags[len(lags) // 2], 4),
                                   "p99": round(lags[min(len(lags) - 1, int(0.99 * len(lags)))], 4),
                                   "max": round(lags[-1], 4),
                                   "windows_over_0.1_s": sum(1 for x in lags if x > 0.1),
                                   "windows_over_0.5_s": sum(1 for x in lags if x > 0.5)}
        with open(os.path.join(out, "stamp_delay.csv"), "w") as f:
            f.write("t_s,earliest_delay_s,latest_delay_s\n")
            f.writelines("%.1f,%.6f,%.6f\n" % d for d in state["delays"])
    if steal:
        report["hypervisor_steal_percent"] = {"mean": round(sum(s for _, s in steal) / len(steal), 1),
                                              "max_10s": round(max(s for _, s in steal), 1)}
    # The driver's own lateness (its log): a late source, not the pipeline, when it coincides.
    behind = driver_lateness(out, state.get("t0", 0.0))
    report["driver_behind_schedule"] = {"warnings": len(behind), "max_s": max((b for _, b in behind), default=0.0),
                                        "over_0.5_s": [[round(t, 1), b] for t, b in behind if b > 0.5][:20]}
    # Each ERROR with the steal of its 10 s interval and the driver's lateness around it.
    state["errors"] = [list(e) + [next((round(s, 1) for t, s in steal if t >= e[0]), None),
                                  max((b for t, b in behind if abs(t - e[0]) <= 15.0), default=0.0)]
                       for e in state["errors"]]
    report["error_diagnostics_columns"] = ["t_s", "status", "message", "steal_percent", "driver_behind_s"]
    report["error_diagnostics"] = state["errors"][:20]
    report["error_diagnostic_count"] = len(state["errors"])
    report["worst_level"] = state["levels"]
    report["calibration_results"] = state["results"]
    report["samples_rss"] = len(warm)
    if lost != 0 or received == 0 or state["errors"]:
        ok = False
    report["passed"] = ok
    with open(os.path.join(out, "soak.yaml"), "w") as f:
        yaml.safe_dump(report, f, sort_keys=False)
    with open(os.path.join(out, "soak.md"), "w") as f:
        f.write("| node | RSS start | after warm-up | end | max | growth | CPU % |\n| --- | --- | --- | --- | --- | --- | --- |\n")
        for name, n in sorted(report["nodes"].items()):
            if isinstance(n, dict):
                f.write("| %s | %.1f | %.1f | %.1f | %.1f | %+.2f | %.1f |\n" % (
                    name, n["rss_start_mib"], n["rss_after_warmup_mib"], n["rss_end_mib"], n["rss_max_mib"],
                    n["growth_after_warmup_mib"], n["cpu_percent"]))
        f.write("\nreceived %s, lost %s, error diagnostics %d, calibration %s\n" % (
            received, lost, len(state["errors"]), state["results"]))
    log("%s; report %s" % ("PASSED" if ok else "FAILED", os.path.join(out, "soak.yaml")))
    print(open(os.path.join(out, "soak.md")).read())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
