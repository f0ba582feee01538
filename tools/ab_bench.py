#!/usr/bin/env python3
"""A/B of `tracelab bench` on a noisy machine: the four bench meshes (../shared/perf, from the
checkout), single rays and 8-ray packets, 800x800, 1 thread, the two binaries alternating (the
order swapped every round), ROUNDS rounds. Prints each binary's tree shape and bytes per
triangle, then per scene and mode the medians over the rounds of Mrays/s and build_ms, the
median of the per-round ratios B / A, and whether hits and sum_t were the same in every run.
Copy the base binary aside first: the binaries are compared as given.

usage: tools/ab_bench.py ROUNDS A B [REPEAT]   (REPEAT: bench's --repeat, default 15)
"""
import os
import re
import statistics
import subprocess
import sys
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
perf = os.path.join(root, "..", "shared", "perf")
rounds, A, B = int(sys.argv[1]), os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
rep = sys.argv[4] if len(sys.argv) > 4 else "15"
scenes = ["bench_cube.txt", "bench_bunny1k.txt", "bench_bunny69k.txt", "bench_dragon871k.txt"]
modes = ["single", "packets"]


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def now():
    return time.strftime("%H:%M:%S", time.gmtime())


def bench(binary, scene, mode):
    args = [binary, "bench", scene, "--size", "800", "800", "--threads", "1", "--repeat", rep]
    if mode == "packets":
        args.append("--packets")
    out = subprocess.run(args, cwd=perf, capture_output=True, text=True, check=True).stdout
    m = re.search(r"BENCH mrays_per_s=(\S+) hits=(\S+) sum_t=(\S+) build_ms=(\S+)", out)
    shape = [l for l in out.splitlines() if l.startswith(("bvh:", "mesh:"))]
    return (float(m[1]), m[2], m[3], float(m[4])), shape


res, shapes = {}, {}
print("start", now(), "UTC, load", load(), flush=True)
for r in range(rounds):
    order = [("A", A), ("B", B)] if r % 2 == 0 else [("B", B), ("A", A)]
    for s in scenes:
        for mode in modes:
            for tag, b in order:
                row, shapes[(s, tag)] = bench(b, s, mode)
                res.setdefault((s, mode, tag), []).append(row)
    print("round", r + 1, "done", now(), "load", load(), flush=True)
print("end", now(), "UTC, load", load())
for s in scenes:
    for tag in "AB":
        print(s, tag, *shapes[(s, tag)], sep=" | ")
print(f"{'scene':22} {'mode':8} {'A Mrays':>8} {'B Mrays':>8} {'B/A':>6} {'A build':>8} {'B build':>8}  checksums")
for s in scenes:
    for mode in modes:
        a, b = res[(s, mode, "A")], res[(s, mode, "B")]
        med = lambda rows, k: statistics.median(x[k] for x in rows)
        ratio = statistics.median(y[0] / x[0] for x, y in zip(a, b))
        sums = {(x[1], x[2]) for x in a + b}
        same = f"same hits={a[0][1]} sum_t={a[0][2]}" if len(sums) == 1 else f"DIFFER {sorted(sums)}"
        print(f"{s:22} {mode:8} {med(a, 0):8.2f} {med(b, 0):8.2f} {ratio:6.3f} "
              f"{med(a, 3):8.2f} {med(b, 3):8.2f}  {same}")
