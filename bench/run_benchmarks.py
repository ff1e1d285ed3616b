#!/usr/bin/env python3
"""`make bench`: runs every benchmark of hrg_gyro and writes bench_output/results.{json,md}.

  1. core suites (Google Benchmark, 5 repetitions, medians): demodulation, wave state, compensation
     with 0/4/8 harmonics and K(theta, f), the whole per-sample processor, fits, simulator RTF,
     the resonator with its loops closed (ns per output sample, RTF), north-finding (an alignment of a 10 min
     window of 200 Hz triad samples, static and indexed: bench/alignment_benchmarks.cpp);
  2. calibration: 24 h of 1 kHz streams through the dual-rate session (time, peak RSS);
  3. offline: `hrg_bag process` (no output, --csv, --out) on bags of 1 M and 5 M samples beside its floor,
     hrg_gyro_bag_read_floor reading the same bag and nothing else (whole processes, wall clock, ratio);
     `rosbag play --immediate` of the 1 M bag into the processor node (processed and dropped counted
     from the node's diagnostics). The bags are simulated once into bench_output/ and reused;
  4. live: driver_sim -> processor at 1, 5 and 10 kHz, separate processes vs nodelets: drops,
     latency p50/p99/max, CPU per process (from /proc);
  5. triad: three simulated gyros at 10 kHz, their processors and the triad in one nodelet manager
     (bench/live_triad.launch, sim time): triad samples against the stamps' sequence, flagged and
     missing ones, the processors' lost input, how far behind /clock, sim time per wall second, CPU.
Environment: BENCH_LIVE_SECONDS (default 60), BENCH_CAL_HOURS (default 24), BENCH_OFFLINE_REPEATS
(default 3, medians), BENCH_ONLY (comma list
of core,calibration,offline,live,triad)."""
import json
import os
import random
import re
import resource
import signal
import subprocess
import sys
import time

import proc_stats

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WS = os.path.join(ROOT, ".ws")
BIN = os.path.join(WS, "devel", "lib", "hrg_gyro")
OUT = os.path.join(ROOT, "bench_output")
CLK = os.sysconf("SC_CLK_TCK")


def log(msg):
    print("bench: " + msg, file=sys.stderr, flush=True)


def machine():
    cpu = "unknown"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    with open("/proc/meminfo") as f:
        mem = int(f.readline().split()[1]) / 1024 / 1024
    return "%s, %d cores, %.0f GiB RAM, %s" % (cpu, os.cpu_count(), mem, os.uname().release)


def core_suites(results):
    log("core suites (Google Benchmark, 5 repetitions)")
    path = os.path.join(OUT, "core.json")
    subprocess.run([os.path.join(BIN, "hrg_gyro_core_bench"), "--benchmark_repetitions=5",
                    "--benchmark_report_aggregates_only=true", "--benchmark_out=" + path,
                    "--benchmark_out_format=json"], check=True, stdout=sys.stderr)
    with open(path) as f:
        data = json.load(f)
    rows = []
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        row = {"name": b["run_name"], "label": b.get("label", ""), "time": b["real_time"], "unit": b["time_unit"]}
        if "items_per_second" in b:
            row["ns_per_item"] = 1e9 / b["items_per_second"]
        if "rtf" in b:
            row["rtf"] = b["rtf"]
        rows.append(row)
    results["core"] = rows


def calibration(results):
    hours = os.environ.get("BENCH_CAL_HOURS", "24")
    log("calibration: %s h of 1 kHz streams" % hours)
    t = time.time()
    p = subprocess.run([os.path.join(BIN, "hrg_gyro_calibration_bench"), hours, "1000"], stdout=subprocess.PIPE,
                       universal_newlines=True)
    print(p.stdout, file=sys.stderr)
    results["calibration"] = {"hours": float(hours), "wall_s": time.time() - t, "output": p.stdout,
                              "exit": p.returncode}


class Master(object):
    """A private master port for each launch (a roscore of the user's is left alone)."""

    def __init__(self):
        self.port = random.randint(20000, 40000)
        self.env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % self.port)


def process_cpu(patterns):
    """utime+stime ticks of the processes whose command line matches each pattern."""
    return {name: ticks for name, (_, ticks) in proc_stats.scan(patterns).items()}


OFFLINE_SIZES = ((1, "1000.0"), (5, "5000.0"))  # millions of samples, session seconds at 1 kHz


def offline_bag(millions, duration):
    """The offline scenario simulated for `duration` s (millions of 1 kHz samples), built once: the bag is
    reused while the scenario text it was made from is unchanged (the 5 M bag takes a minute or more;
    delete bench_output/offline_*.bag to simulate them again)."""
    with open(os.path.join(ROOT, "bench", "offline_scenario.yaml")) as f:
        scenario = f.read()
    if "duration: 1000.0" not in scenario:
        raise RuntimeError("bench/offline_scenario.yaml: its profile must say 'duration: 1000.0'")
    scenario = scenario.replace("duration: 1000.0", "duration: " + duration)
    bag = os.path.join(OUT, "offline_%dM.bag" % millions)
    recipe = bag + ".scenario.yaml"
    if os.path.exists(bag) and os.path.exists(recipe):
        with open(recipe) as f:
            if f.read() == scenario:
                log("offline: reusing %s" % bag)
                return bag
    log("offline: simulating a %d M-sample bag (once; reused by later runs)" % millions)
    with open(recipe, "w") as f:
        f.write(scenario)
    t = time.time()
    subprocess.run([os.path.join(BIN, "hrg_bag"), "simulate", "--scenario", recipe, "--out", bag, "--no-truth"],
                   check=True, stderr=subprocess.PIPE)
    log("  simulated in %.0f s" % (time.time() - t))
    return bag


def timed(argv, pattern):
    """Runs argv as a whole process BENCH_OFFLINE_REPEATS times (default 3): the median wall clock
    (startup and exit included), the median CPU time (user + system, steadier on a shared machine)
    and the sample count it prints."""
    walls, cpus = [], []
    for _ in range(int(os.environ.get("BENCH_OFFLINE_REPEATS", "3"))):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.time()
        p = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, check=True)
        walls.append(time.time() - t)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        n = int(re.search(pattern, p.stdout + p.stderr).group(1))
    return n, sorted(walls)[len(walls) // 2], sorted(cpus)[len(cpus) // 2]


def offline(results):
    """hrg_bag process beside its floor (reading the same bag and nothing else), side by side on 1 M and
    5 M samples: samples/s as whole processes and the ratio of the wall clocks to the floor's."""
    params = os.path.join(ROOT, "config", "params_uncalibrated.yaml")
    floor_bin = os.path.join(BIN, "hrg_gyro_bag_read_floor")
    out = {"sizes": {}}
    for millions, duration in OFFLINE_SIZES:
        bag = offline_bag(millions, duration)
        size = {}
        for mode in ("reused", "instantiate", "view"):
            n, wall, cpu = timed([floor_bin, bag, mode], r"floor \w+: (\d+) messages")
            size["floor_" + mode] = {"samples": n, "wall_s": wall, "cpu_s": cpu, "samples_per_s": n / wall}
        floor_wall, floor_cpu = size["floor_reused"]["wall_s"], size["floor_reused"]["cpu_s"]
        for variant, args in (("dry", []),
                              ("csv", ["--csv", os.path.join(OUT, "offline_out.csv")]),
                              ("bag", ["--out", os.path.join(OUT, "offline_out.bag")]),
                              ("bag_uncompressed", ["--out", os.path.join(OUT, "offline_out.bag"), "--compression",
                                                    "none"])):
            n, wall, cpu = timed([os.path.join(BIN, "hrg_bag"), "process", bag, "--params", params] + args,
                                 r"done, (\d+) samples")
            size["process_" + variant] = {"samples": n, "wall_s": wall, "cpu_s": cpu, "samples_per_s": n / wall,
                                          "ratio_to_floor": wall / floor_wall, "cpu_ratio_to_floor": cpu / floor_cpu}
        for name in ("offline_out.csv", "offline_out.bag"):  # gigabytes at 5 M samples
            if os.path.exists(os.path.join(OUT, name)):
                os.remove(os.path.join(OUT, name))
        for k, v in sorted(size.items()):
            log("  %d M %-26s %9.0f samples/s %7.2f s wall %7.2f s CPU%s" % (
                millions, k, v["samples_per_s"], v["wall_s"], v["cpu_s"],
                "  %.2fx the floor (CPU %.2fx)" % (v["ratio_to_floor"], v["cpu_ratio_to_floor"])
                if "ratio_to_floor" in v else ""))
        out["sizes"]["%dM" % millions] = size
    bag = offline_bag(*OFFLINE_SIZES[0])
    # The playback path: rosbag play --immediate into the processor node.
    log("offline: rosbag play --immediate into the processor node")
    master = Master()
    # ns:=/ : the bag's topics are global (/channels), processor.launch's default namespace is gyro.
    launch = subprocess.Popen(["roslaunch", "-p", str(master.port), "hrg_gyro", "processor.launch", "ns:=/",
                               "parameter_file:=" + params, "expected_rate:=1000"], env=master.env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, preexec_fn=os.setsid)
    seen = {"received": 0, "lost": 0, "updated": time.time()}
    try:
        # This process listens to the processor's diagnostics on the private master.
        os.environ["ROS_MASTER_URI"] = master.env["ROS_MASTER_URI"]
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray

        def on_diagnostics(msg):
            for status in msg.status:
                for kv in status.values:
                    if kv.key == "received" and int(kv.value) != seen["received"]:
                        seen["received"], seen["updated"] = int(kv.value), time.time()
                    elif kv.key == "lost (sequence gaps)":
                        seen["lost"] = int(kv.value)

        time.sleep(5)
        rospy.init_node("bench_offline", anonymous=True, disable_signals=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=100)
        time.sleep(2)
        t = time.time()
        subprocess.run(["rosbag", "play", "--immediate", "-q", bag, "--topics", "/channels"], env=master.env,
                       check=True, stdout=subprocess.DEVNULL)
        play_wall = time.time() - t
        while time.time() - seen["updated"] < 3.0:  # until the count has settled
            time.sleep(0.5)
        rospy.signal_shutdown("done")
    finally:
        os.killpg(launch.pid, signal.SIGINT)
        launch.wait(timeout=30)
    processed = seen["received"]
    total = out["sizes"]["1M"]["process_dry"]["samples"]
    out["playback"] = {"published": total, "processed": processed, "dropped": total - processed,
                       "play_wall_s": play_wall, "processed_per_s": processed / play_wall}
    log("  playback: %d of %d processed in %.1f s" % (processed, total, play_wall))
    results["offline"] = out


def live(results):
    seconds = float(os.environ.get("BENCH_LIVE_SECONDS", "60"))
    rows = []
    for rate, frequency, ppo in ((1000, 5000.0, 5), (5000, 5000.0, 1), (10000, 10000.0, 1)):
        for nodelets in (False, True):
            mode = "nodelets" if nodelets else "processes"
            log("live: %d Hz, %s, %.0f s" % (rate, mode, seconds))
            master = Master()
            result = os.path.join(OUT, "live_%d_%s.yaml" % (rate, mode))
            if os.path.exists(result):
                os.remove(result)
            launch = subprocess.Popen(["roslaunch", "-p", str(master.port), "hrg_gyro", "live_pipeline.launch",
                                       "frequency:=%s" % frequency, "periods_per_output:=%d" % ppo,
                                       "use_nodelets:=%s" % str(nodelets).lower(), "duration:=%s" % seconds,
                                       "result_file:=" + result], env=master.env, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL, preexec_fn=os.setsid)
            patterns = ({"manager": "__name:=gyro_manager"} if nodelets else
                        {"driver_sim": "__name:=driver_sim", "processor": "__name:=processor"})
            patterns["latency_probe"] = "__name:=latency_probe"
            time.sleep(8)
            first, t_first = process_cpu(patterns), time.time()
            last = {k: (v, t_first) for k, v in first.items()}
            while launch.poll() is None:
                time.sleep(1)
                now = time.time()
                for k, v in process_cpu(patterns).items():
                    last[k] = (v, now)
            cpu = {k: 100.0 * (last[k][0] - first[k]) / CLK / max(last[k][1] - t_first, 1e-9)
                   for k in first if k in last}
            row = {"rate": rate, "mode": mode, "cpu_percent": cpu}
            if os.path.exists(result):
                with open(result) as f:
                    for line in f:
                        k, v = line.split(":", 1)
                        row.setdefault(k.strip(), v.strip())
            rows.append(row)
            log("  %s" % row)
    results["live"] = rows


def live_triad(results):
    """Three gyros at 10 kHz through one manager: every stamp combined, nothing lost, on time."""
    seconds = float(os.environ.get("BENCH_LIVE_SECONDS", "60"))
    log("triad: three gyros at 10 kHz, processors and triad in one manager, %.0f s" % seconds)
    master = Master()
    result = os.path.join(OUT, "live_triad.yaml")
    if os.path.exists(result):
        os.remove(result)
    launch = subprocess.Popen(["roslaunch", "-p", str(master.port), "hrg_gyro", "live_triad.launch",
                               "frequency:=10000.0", "periods_per_output:=1", "duration:=%s" % seconds,
                               "result_file:=" + result], env=master.env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, preexec_fn=os.setsid)
    patterns = {"manager": "__name:=triad_manager", "triad_probe": "__name:=triad_probe"}
    time.sleep(8)
    first, t_first = process_cpu(patterns), time.time()
    last = {k: (v, t_first) for k, v in first.items()}
    while launch.poll() is None:
        time.sleep(1)
        now = time.time()
        for k, v in process_cpu(patterns).items():
            last[k] = (v, now)
    cpu = {k: 100.0 * (last[k][0] - first[k]) / CLK / max(last[k][1] - t_first, 1e-9) for k in first if k in last}
    row = {"rate": 10000, "cpu_percent": cpu}
    if os.path.exists(result):
        with open(result) as f:
            for line in f:
                k, v = line.split(":", 1)
                row.setdefault(k.strip(), v.strip())
    log("  %s" % row)
    results["triad"] = row


def markdown(results):
    lines = ["# hrg_gyro benchmark results", "", "Machine: " + results["machine"], "Date: " + results["date"], ""]
    if "core" in results:
        lines += ["## Core (median of 5 repetitions)", "", "| benchmark | case | median | per item | RTF |",
                  "| --- | --- | --- | --- | --- |"]
        for r in results["core"]:
            lines.append("| %s | %s | %.4g %s | %s | %s |" % (
                r["name"], r["label"], r["time"], r["unit"],
                "%.1f ns" % r["ns_per_item"] if "ns_per_item" in r else "",
                "%.0fx" % r["rtf"] if "rtf" in r else ""))
    if "calibration" in results:
        lines += ["", "## Calibration", "", "```", results["calibration"]["output"].rstrip(), "```"]
    if "offline" in results:
        o = results["offline"]
        names = (("floor_reused", "floor: rosbag::View, deserialised into a reused message"),
                 ("floor_instantiate", "floor: rosbag::View, MessageInstance::instantiate"),
                 ("floor_view", "rosbag::View iteration alone (no message data)"),
                 ("process_dry", "hrg_bag process (no output files)"), ("process_csv", "hrg_bag process --csv"),
                 ("process_bag", "hrg_bag process --out (LZ4)"),
                 ("process_bag_uncompressed", "hrg_bag process --out --compression none"))
        lines += ["", "## Offline: hrg_bag process beside the floor (whole processes, median of %s runs)" %
                  os.environ.get("BENCH_OFFLINE_REPEATS", "3"), "",
                  "Ratios: wall clock (and CPU time, user + system) over the reused-message floor's on the same bag.",
                  "", "| path | " + " | ".join("%s samples/s | x floor (CPU)" % k for k in o["sizes"]) + " |",
                  "| --- |" + " --- | --- |" * len(o["sizes"])]
        for k, name in names:
            cells = []
            for size in o["sizes"].values():
                r = size[k]
                cells.append("%.0f | %s" % (r["samples_per_s"], "%.2f (%.2f)" % (
                    r["ratio_to_floor"], r["cpu_ratio_to_floor"]) if "ratio_to_floor" in r else "-"))
            lines.append("| %s | %s |" % (name, " | ".join(cells)))
        lines += ["", "| path | samples/s | notes |", "| --- | --- | --- |"]
        p = o["playback"]
        lines.append("| rosbag play --immediate -> processor node | %.0f | %d processed, %d dropped of %d, %.1f s |" % (
            p["processed_per_s"], p["processed"], p["dropped"], p["published"], p["play_wall_s"]))
    if "live" in results:
        lines += ["", "## Live pipeline", "", "| rate | mode | outputs | missing | input lost | p50 ms | p99 ms | max ms | CPU % |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in results["live"]:
            lines.append("| %d Hz | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                r["rate"], r["mode"], r.get("outputs", "-"), r.get("outputs_missing", "-"),
                r.get("processor_input_lost", "-"), r.get("latency_p50_ms", "-"), r.get("latency_p99_ms", "-"),
                r.get("latency_max_ms", "-"), ", ".join("%s %.1f" % kv for kv in sorted(r["cpu_percent"].items()))))
    if "triad" in results:
        r = results["triad"]
        lines += ["", "## Live triad: three gyros, processors and triad in one manager", "",
                  "| rate per axis | triad samples / expected | combined | flagged | stamps missing | processors' input lost "
                  "| sim s per wall s | behind /clock p50 / p99 / max ms | CPU % |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
                  "| %d Hz | %s / %s | %s | %s | %s | %s | %s | %s / %s / %s | %s |" % (
                      r["rate"], r.get("samples", "-"), r.get("expected", "-"), r.get("combined", "-"),
                      r.get("flagged", "-"), r.get("stamps_missing", "-"), r.get("processors_input_lost", "-"),
                      r.get("sim_per_wall", "-"), r.get("behind_clock_p50_ms", "-"), r.get("behind_clock_p99_ms", "-"),
                      r.get("behind_clock_max_ms", "-"),
                      ", ".join("%s %.1f" % kv for kv in sorted(r["cpu_percent"].items())))]
    return "\n".join(lines) + "\n"


def main():
    os.makedirs(OUT, exist_ok=True)
    only = os.environ.get("BENCH_ONLY", "core,calibration,offline,live,triad").split(",")
    results = {"machine": machine(), "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    for name, fn in (("core", core_suites), ("calibration", calibration), ("offline", offline), ("live", live),
                     ("triad", live_triad)):
        if name in only:
            fn(results)
    with open(os.path.join(OUT, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    md = markdown(results)
    with open(os.path.join(OUT, "results.md"), "w") as f:
        f.write(md)
    print(md)


if __name__ == "__main__":
    main()
