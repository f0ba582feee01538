#!/usr/bin/env python3
"""A/B of `tracelab bench` on a noisy machine: the four bench meshes (../shared/perf, from the
checkout), single rays and 8-ray packets, 800x800, 1 thread, the binaries in turn (the order
rotated every round), ROUNDS rounds. Prints each binary's tree shape and bytes per triangle,
then per scene and mode the medians over the rounds of Mrays/s and build_ms, the median of the
per-round ratios to the first binary (A), and whether hits and sum_t were the same in every
run. Copy the base binary aside first: the binaries are compared as given.

usage: tools/ab_bench.py ROUNDS A B [C ...] [--repeat N] [--single]
       (--repeat: bench's --repeat, default 15; --single: single rays only, no packets)
"""
import os
import re
import statistics
import subprocess
import sys
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
perf = os.path.join(root, "..", "shared", "perf")
args = sys.argv[1:]
rep = "15"
if "--repeat" in args:
    i = args.index("--repeat")
    rep = args[i + 1]
    del args[i : i + 2]
single = "--single" in args
if single:
    args.remove("--single")
if len(args) < 3 or not args[0].isdigit():
    sys.exit(__doc__)
rounds, bins = int(args[0]), [os.path.abspath(b) for b in args[1:]]
tags = [chr(ord("A") + i) for i in range(len(bins))]
scenes = ["bench_cube.txt", "bench_bunny1k.txt", "bench_bunny69k.txt", "bench_dragon871k.txt"]
modes = ["single"] if single else ["single", "packets"]


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
    k = r % len(bins)
    order = list(zip(tags, bins))[k:] + list(zip(tags, bins))[:k]
    for s in scenes:
        for mode in modes:
            for tag, b in order:
                row, shapes[(s, tag)] = bench(b, s, mode)
                res.setdefault((s, mode, tag), []).append(row)
    print("round", r + 1, "done", now(), "load", load(), flush=True)
print("end", now(), "UTC, load", load())
for tag, b in zip(tags, bins):
    print(tag, "=", b)
for s in scenes:
    for tag in tags:
        print(s, tag, *shapes[(s, tag)], sep=" | ")
med = lambda rows, k: statistics.median(x[k] for x in rows)
head = "".join(f" {t + ' Mrays':>9} {t + '/A':>6} {t + ' build':>8}" for t in tags)
print(f"{'scene':22} {'mode':8}{head}  checksums")
for s in scenes:
    for mode in modes:
        a = res[(s, mode, "A")]
        line = f"{s:22} {mode:8}"
        for t in tags:
            x = res[(s, mode, t)]
            ratio = statistics.median(q[0] / p[0] for p, q in zip(a, x))
            line += f" {med(x, 0):9.2f} {ratio:6.3f} {med(x, 3):8.2f}"
        rows = [row for t in tags for row in res[(s, mode, t)]]
        sums = {(x[1], x[2]) for x in rows}
        same = f"same hits={a[0][1]} sum_t={a[0][2]}" if len(sums) == 1 else f"DIFFER {sorted(sums)}"
        print(f"{line}  {same}")
