#!/usr/bin/env python3
"""A/B of the editor's first coarse image on a noisy machine: `tracelab bench-progressive`
(2 threads, medians of 7) for each binary in turn, ROUNDS rounds alternating, then per binary
the median over the rounds of coarse_ms and full_ms, with the load average before and after.
Copy the base binary aside first: the binaries are compared as given.

usage: tools/ab_progressive.py ROUNDS BINARY... [--scene SCENE] [--args "extra bench args"]
       (SCENE defaults to ../shared/perf/bench_dragon871k.txt, from the checkout)
"""
import argparse
import os
import re
import statistics
import subprocess
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser()
ap.add_argument("rounds", type=int)
ap.add_argument("binaries", nargs="+")
ap.add_argument("--scene", default="../shared/perf/bench_dragon871k.txt")
ap.add_argument("--args", default="")
a = ap.parse_args()


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def field(name, out):
    m = re.search(name + r"=([\d.]+)", out)
    if not m:
        raise SystemExit(f"no {name} in:\n{out}")
    return float(m.group(1))


print("start", time.strftime("%H:%M:%S", time.gmtime()), "UTC, load", load(), "scene", a.scene)
runs = {b: [] for b in a.binaries}
for _ in range(a.rounds):
    for b in a.binaries:
        cmd = [b, "bench-progressive", a.scene, "--threads", "2", "--repeat", "7", *a.args.split()]
        out = subprocess.run(cmd, cwd=root, capture_output=True, text=True, check=True).stdout
        runs[b].append((field("coarse_ms", out), field("full_ms", out)))
print("end  ", time.strftime("%H:%M:%S", time.gmtime()), "UTC, load", load())
for b, rs in runs.items():
    cs = " ".join(f"{c:.2f}" for c, _ in rs)
    print(
        f"{b}: coarse median {statistics.median(c for c, _ in rs):.2f} ms ({cs}), "
        f"full median {statistics.median(f for _, f in rs):.2f} ms"
    )
