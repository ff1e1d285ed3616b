"""Resident memory and CPU time of running processes, read from /proc (benchmarks and soak)."""
import os

CLK_TCK = os.sysconf("SC_CLK_TCK")


def scan(patterns):
    """{name: (VmRSS in MiB, utime+stime ticks)}, summed over the processes whose command line
    contains patterns[name] (roslaunch itself, whose arguments may name the nodes, excluded)."""
    found = {}
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                cmd = f.read().replace(b"\0", b" ").decode(errors="replace")
            names = [n for n, p in patterns.items() if p in cmd]
            if not names or "roslaunch" in cmd:
                continue
            with open("/proc/%s/status" % pid) as f:
                rss = next(int(line.split()[1]) for line in f if line.startswith("VmRSS:")) / 1024.0
            with open("/proc/%s/stat" % pid) as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except (IOError, OSError, StopIteration):
            continue  # the process ended while we read it
        for name in names:
            old = found.get(name, (0.0, 0))
            found[name] = (old[0] + rss, old[1] + int(fields[11]) + int(fields[12]))
    return found


def cpu_times():
    """(all ticks, steal ticks) of the machine since boot, from /proc/stat: steal is the time the
    hypervisor ran something else while this VM's CPUs had work."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    return sum(fields), fields[7] if len(fields) > 7 else 0
