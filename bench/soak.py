#!/usr/bin/env python3
"""Soak test (`make soak`): a long simulated session at 10 kHz through driver_sim, processor and
calibrator, with the resident memory of the nodes sampled and every diagnostic watched.

Environment: SOAK_SECONDS (simulated seconds, default 3600), SOAK_MODE (nodelets | processes,
default nodelets), SOAK_RATE (channel rate in Hz, default 10000), SOAK_OUT (default
bench_output/soak), SOAK_CLOCK (sim | wall, default sim) and SOAK_TIME_SCALE (sim only, default 2:
measured to keep up on 2 cores).

SOAK_CLOCK=sim: driver_sim drives /clock, so when the host deschedules the whole VM (hypervisor
steal) the simulated clock slows with it and every delay the nodes report is the pipeline's own;
the run lasts until driver_sim says the scenario is done. SOAK_CLOCK=wall: stamps follow the wall
clock, as with hardware; a host stall then shows as late input (ERROR "timestamps too far in
past") although nothing is lost, and the run lasts SOAK_SECONDS of wall time.
Writes SOAK_OUT/soak.yaml, soak.md, rss.csv (RSS and hypervisor steal), heap.csv (live heap) and
stamp_delay.csv; exits non-zero when the session lost samples, a diagnostic went to ERROR after the
start-up, the sim-clock scenario did not finish, or memory grew: the median RSS of the tenth of the
session before the calibration result exceeding that of the tenth after the warm-up (the first tenth)
by more than SOAK_RSS_GROWTH_MIB (default 2 MiB).
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


def rosout_lines(out):
    """This run's rosout.log (found through the log directory roslaunch names in its output)."""
    try:
        with open(os.path.join(out, "roslaunch.log")) as f:
            head = f.read(4000)
        logdir = os.path.dirname(re.search(r"logging to (\S+)", head).group(1))
        with open(os.path.join(logdir, "rosout.log")) as f:
            return f.readlines()
    except (IOError, OSError, AttributeError):
        return []


def driver_lateness(lines, t0):
    """[(t since t0, seconds behind)] from driver_sim's "behind schedule" warnings (wall clock)."""
    found = []
    for line in lines:
        m = re.match(r"(\d+\.\d+) WARN .*driver_sim: ([0-9.]+) s behind schedule", line)
        if m:
            found.append((float(m.group(1)) - t0, float(m.group(2))))
    return found


def driver_completion(lines):
    """driver_sim's "scenario complete" line: simulated and wall seconds, and under sim time the
    wall seconds its schedule let go (the VM was descheduled) and in how many pauses."""
    for line in lines:
        m = re.search(r"scenario complete: (\d+) samples, ([0-9.]+) s simulated in ([0-9.]+) s of wall time"
                      r"(?: \(([0-9.]+)x\))?(?:, the schedule let go ([0-9.]+) s in (\d+) pauses)?", line)
        if m:
            r = {"samples": int(m.group(1)), "simulated_s": float(m.group(2)), "wall_s": float(m.group(3))}
            if m.group(5):
                r.update(schedule_let_go_s=float(m.group(5)), pauses=int(m.group(6)))
            return r
    return None


def median(values):
    values = sorted(values)
    return values[len(values) // 2] if values else float("nan")


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
    rest = max(60.0, seconds - 10.0 - 452.0 * repeat)
    s["turntable"]["profile"] = [
        {"type": "dwell", "duration": 10.0, "label": "start"},
        {"type": "dual_rate", "rates": [0.05, -0.05], "duration": 226.0, "settle": 3.0, "repeat": repeat,
         "label": "calibration"},
        {"type": "dwell", "duration": rest, "label": "rest"},
    ]
    return s, frequency / s["resonator"]["periods_per_output"], 10.0 + 452.0 * repeat + rest


def main():
    seconds = float(os.environ.get("SOAK_SECONDS", "3600"))
    mode = os.environ.get("SOAK_MODE", "nodelets")
    rate = float(os.environ.get("SOAK_RATE", "10000"))
    growth_limit = float(os.environ.get("SOAK_RSS_GROWTH_MIB", "2.0"))
    clock = os.environ.get("SOAK_CLOCK", "sim")
    if clock not in ("sim", "wall"):
        raise SystemExit("SOAK_CLOCK must be sim or wall")
    time_scale = float(os.environ.get("SOAK_TIME_SCALE", "2")) if clock == "sim" else 1.0
    out = os.environ.get("SOAK_OUT", os.path.join(ROOT, "bench_output", "soak"))
    os.makedirs(out, exist_ok=True)
    scen, output_rate, duration = scenario(seconds, rate)
    if clock == "sim":
        seconds = duration  # the whole scenario (never shorter than 522 s), however long it takes
    scen_file = os.path.join(out, "scenario.yaml")
    with open(scen_file, "w") as f:
        yaml.safe_dump(scen, f)
    params = os.path.join(out, "params.yaml")
    shutil.copy(os.path.join(ROOT, "config", "params_uncalibrated.yaml"), params)

    port = random.randint(20000, 40000)
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
    log("%.0f s at %.0f Hz as %s, %s clock (time scale %g); output in %s" % (
        seconds, output_rate, mode, clock, time_scale, out))
    launch = subprocess.Popen(["roslaunch", "-p", str(port), os.path.join(ROOT, "bench", "soak.launch"),
                               "scenario:=" + scen_file, "parameter_file:=" + params,
                               "use_nodelets:=%s" % str(mode == "nodelets").lower(),
                               "output_rate:=%s" % output_rate,
                               "use_sim_time:=%s" % str(clock == "sim").lower(), "time_scale:=%g" % time_scale],
                              env=env, stdout=open(os.path.join(out, "roslaunch.log"), "w"),
                              stderr=subprocess.STDOUT, preexec_fn=os.setsid)
    patterns = ({"manager": "__name:=gyro_manager"} if mode == "nodelets" else
                {"driver_sim": "__name:=driver_sim", "processor": "__name:=processor",
                 "calibrator": "__name:=calibrator"})
    samples, steal = [], []  # steal: (t, % of the VM's CPU time the hypervisor took in the interval)
    state = {"errors": [], "levels": {}, "processor": {}, "results": [], "delays": [], "heap": [], "done": False}
    try:
        time.sleep(5)
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
        from hrg_gyro.msg import CalibrationResult
        from std_msgs.msg import Bool

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
            state.setdefault("result_t", time.time() - state.get("t0", time.time()))
            state["results"].append({"accepted": msg.accepted, "written": msg.written, "reason": msg.reason,
                                     "nonlinearity_ppm": msg.nonlinearity_ppm, "duration_s": msg.duration,
                                     "samples": msg.samples, "coverage": msg.coverage})
            log("calibration result: accepted=%s written=%s %s" % (msg.accepted, msg.written, msg.reason))

        rospy.init_node("soak_monitor", anonymous=True, disable_signals=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=100)
        rospy.Subscriber("/calibrator/result", CalibrationResult, on_result, queue_size=10)
        rospy.Subscriber("/driver_sim/done", Bool, lambda m: state.update(done=state["done"] or m.data), queue_size=1)
        t0 = state["t0"] = time.time()
        # Sim clock: until driver_sim is done (it may run slower than time_scale when descheduled).
        wall_limit = seconds if clock == "wall" else 1.5 * seconds / time_scale + 120.0
        cpu_before = proc_stats.cpu_times()
        next_report = t0 + 60
        while time.time() - t0 < wall_limit and launch.poll() is None and not state["done"]:
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
    report = {"seconds": seconds, "mode": mode, "clock": clock, "time_scale": time_scale,
              "wall_seconds": round(samples[-1][0], 1) if samples else 0.0, "output_rate_hz": output_rate,
              "nodes": {}}
    ok = True
    warmup = 0.1 * seconds / time_scale  # wall seconds: the first tenth of the session
    # Memory is compared in one state of the session: the calibrator holds its buffers until its
    # result, then frees them, so "late" is the tenth before the result (or before the end).
    steady_end = state.get("result_t", samples[-1][0] if samples else 0.0)
    warm = [s for s in samples if s[0] >= warmup]
    for name in sorted(patterns):
        series = [(t, now[name]) for t, now in samples if name in now]
        if not series:
            ok = False
            report["nodes"][name] = "never seen"
            continue
        early = median([v[0] for t, v in series if warmup <= t < 2 * warmup])
        late = median([v[0] for t, v in series if steady_end - warmup <= t <= steady_end])
        cpu = 100.0 * (series[-1][1][1] - series[0][1][1]) / proc_stats.CLK_TCK / max(series[-1][0] - series[0][0], 1e-9)
        node = {"rss_start_mib": round(series[0][1][0], 2),
                "rss_end_mib": round(series[-1][1][0], 2), "rss_max_mib": round(max(v[0] for _, v in series), 2),
                "rss_early_median_mib": round(early, 2), "rss_late_median_mib": round(late, 2),
                "growth_mib": round(late - early, 2), "cpu_percent": round(cpu, 1)}
        report["nodes"][name] = node
        if not node["growth_mib"] <= growth_limit:  # NaN (no samples in a window) fails too
            ok = False
    p = state["processor"]
    received = int(p.get("received", 0))
    lost = int(p.get("lost (sequence gaps)", -1))
    report["processor"] = {k: p.get(k) for k in ("received", "lost (sequence gaps)", "outputs", "rejected non-finite",
                                                 "rejected degenerate", "rejected jumps", "gaps not integrated")}
    report["expected_samples"] = int(round(output_rate * (seconds if clock == "sim" else
                                                          (samples[-1][0] if samples else 0))))
    with open(os.path.join(out, "heap.csv"), "w") as f:
        f.write("t_s,heap_in_use_mib\n")
        f.writelines("%.1f,%.3f\n" % h for h in state["heap"])
    heap_warm = [h for t, h in state["heap"] if t >= warmup]
    heap_steady = [h for t, h in state["heap"] if warmup <= t < steady_end]
    if heap_warm and heap_steady:
        # Live malloc bytes of the process holding the processor (the whole manager for nodelets):
        # what a leak would raise, whatever the allocator keeps resident.
        report["heap_in_use_mib"] = {"after_warmup": round(heap_steady[0], 2),
                                     "before_result": round(heap_steady[-1], 2), "end": round(heap_warm[-1], 2),
                                     "max": round(max(heap_warm), 2),
                                     "growth": round(heap_steady[-1] - heap_steady[0], 2)}
    lags = sorted(max(abs(e), abs(l)) for _, e, l in state["delays"])
    if lags:
        report["stamp_delay_s"] = {"windows": len(lags), "median": round(median(lags), 4),
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
    lines = rosout_lines(out)
    report["driver_completion"] = driver_completion(lines)
    behind = driver_lateness(lines, state.get("t0", 0.0))
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
    report["calibration_result_at_s"] = round(state["result_t"], 1) if "result_t" in state else None
    report["samples_rss"] = len(warm)
    if lost != 0 or received == 0 or state["errors"]:
        ok = False
    if clock == "sim" and not state["done"]:
        ok = False
        report["not_done"] = "driver_sim did not finish the scenario within %.0f s of wall time" % wall_limit
    report["passed"] = ok
    with open(os.path.join(out, "soak.yaml"), "w") as f:
        yaml.safe_dump(report, f, sort_keys=False)
    with open(os.path.join(out, "soak.md"), "w") as f:
        f.write("| node | RSS start | early (median) | late (median) | growth | max | after the run | CPU % |\n"
                "| --- | --- | --- | --- | --- | --- | --- | --- |\n")
        for name, n in sorted(report["nodes"].items()):
            if isinstance(n, dict):
                f.write("| %s | %.1f | %.1f | %.1f | %+.2f | %.1f | %.1f | %.1f |\n" % (
                    name, n["rss_start_mib"], n["rss_early_median_mib"], n["rss_late_median_mib"], n["growth_mib"],
                    n["rss_max_mib"], n["rss_end_mib"], n["cpu_percent"]))
        f.write("\nreceived %s, lost %s, error diagnostics %d, calibration %s\n" % (
            received, lost, len(state["errors"]), state["results"]))
    log("%s; report %s" % ("PASSED" if ok else "FAILED", os.path.join(out, "soak.yaml")))
    print(open(os.path.join(out, "soak.md")).read())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
