#!/usr/bin/env python3
"""Single rays on a shared host, split by what the host's cache was doing at the time.

usage: tools/spell_ab.py ROUNDS SCENE SPEC [SPEC...]
  SCENE  a bench scene of ../shared/perf without .txt (bench_bunny69k, bench_dragon871k, ...)
  SPEC   a tracelab binary, optionally with one environment setting: TRACELAB_SIMD=avx:PATH;
         or `tb` for tinybvh's BVH8_CPU on the same rays (/tmp/tinybvh_bench, which
         ../shared/perf/compare.sh builds)

Each round runs every SPEC once, in an order rotated from round to round, with a cache probe
before and after each: a pointer chase over 8 MB (in L3 it takes about 20 ns a step here; when
the host's other tenants have evicted it, 50-150 ns). A round whose probes' median is over
50 ns counts as contended. Per SPEC: the median best frame (Mrays/s, `bench --threads 1
--repeat 7`), how many of its processes were slow (under 88% of its best process), and the
per-round ratios to the first SPEC, in quiet rounds, contended rounds and all of them.
Needs gcc (the probe is compiled into a temporary folder). See docs/perf.md, "Zen 4's slow
spells".
"""
import os
import re
import statistics
import subprocess
import sys
import tempfile

PROBE_C = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + t.tv_nsec * 1e-9; }
int main(void) {
  size_t n = (8u << 20) / sizeof(size_t), *ring = malloc(n * sizeof(size_t)), *perm = malloc(n * sizeof(size_t));
  if (!ring || !perm) return 1;
  for (size_t i = 0; i < n; i++) perm[i] = i;
  srand(1);
  for (size_t i = n - 1; i > 0; i--) { size_t j = ((size_t)rand() * RAND_MAX + rand()) % (i + 1), t = perm[i]; perm[i] = perm[j]; perm[j] = t; }
  for (size_t i = 0; i < n; i++) ring[perm[i]] = perm[(i + 1) % n];
  size_t p = 0; long steps = 800000;
  for (long i = 0; i < 100000; i++) p = ring[p];
  double t0 = now();
  for (long i = 0; i < steps; i++) p = ring[p];
  printf("chase_ns=%.3f %zu\n", (now() - t0) / steps * 1e9, p & 1);
  return 0;
}
"""

PERF = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "perf")
MESHES = os.path.join(PERF, "..", "meshes")


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    rounds, scene, specs = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    if any(s == "tb" for s in specs) and not os.access("/tmp/tinybvh_bench", os.X_OK):
        sys.exit("spell_ab: no /tmp/tinybvh_bench (../shared/perf/compare.sh builds it)")
    tmp = tempfile.mkdtemp(prefix="spell_ab.")
    probe = os.path.join(tmp, "probe")
    with open(probe + ".c", "w") as f:
        f.write(PROBE_C)
    subprocess.run(["gcc", "-O2", "-o", probe, probe + ".c"], check=True)
    path = os.path.join(PERF, f"{scene}.txt")
    if not os.path.isfile(path):
        sys.exit(f"spell_ab: no scene {path} (../shared/perf beside the project?)")
    txt = open(path).read()
    g = lambda pat: re.search(pat, txt).group(1).split()
    tb_args = [g(r"obj_file \.\./meshes/(\S+)")[0], "--scale", *g(r"UniformScale (.*)"),
               "--translate", *g(r"Translate (.*)"), "--center", *g(r"center (.*)"),
               "--direction", *g(r"direction (.*)\n"), "--up", "0", "1", "0", "--angle", "30",
               "--size", "800", "800", "--reps", "7", "--threads", "1"]

    def chase():
        out = subprocess.run([probe], capture_output=True, text=True).stdout
        return float(re.search(r"chase_ns=([0-9.]+)", out).group(1))

    def run(spec):
        if spec == "tb":
            out = subprocess.run(["/tmp/tinybvh_bench", *tb_args], cwd=MESHES,
                                 capture_output=True, text=True).stdout
            return float(re.search(r"^BVH8_CPU +1 thread.* ([0-9.]+) Mrays", out, re.M).group(1))
        env, path = dict(os.environ), spec
        if ":" in spec and "=" in spec.split(":")[0]:
            kv, path = spec.split(":", 1)
            k, v = kv.split("=", 1)
            env[k] = v
        out = subprocess.run([path, "bench", f"{scene}.txt", "--size", "800", "800",
                              "--threads", "1", "--repeat", "7"], cwd=PERF, env=env,
                             capture_output=True, text=True).stdout
        return float(re.search(r"best [0-9.]+ ms \(([0-9.]+) Mrays/s\)", out).group(1))

    rows = []
    for r in range(rounds):
        n = len(specs)
        order = [(r + i) % n for i in range(n)]
        res, probes = [0.0] * n, [chase()]
        for i in order:
            res[i] = run(specs[i])
            probes.append(chase())
        c = statistics.median(probes)
        rows.append((c, res))
        print(f"round {r}: chase {c:6.1f} ns  " + "  ".join(f"[{i}] {x:6.2f}" for i, x in enumerate(res)),
              flush=True)
    for i, spec in enumerate(specs):
        v = [res[i] for _, res in rows]
        slow = sum(x < 0.88 * max(v) for x in v)
        print(f"[{i}] {spec}: median {statistics.median(v):.2f} Mrays/s (min {min(v):.2f}, max "
              f"{max(v):.2f}); slow processes {slow}/{len(v)}")
    for name, keep in (("quiet", lambda c: c <= 50), ("contended", lambda c: c > 50), ("all", lambda c: True)):
        sel = [res for c, res in rows if keep(c)]
        if not sel:
            continue
        parts = []
        for i in range(len(specs)):
            v = [x[i] for x in sel]
            part = f"[{i}] {statistics.median(v):.2f}"
            if i:
                part += f" (÷[0] {statistics.median([x[i] / x[0] for x in sel]):.3f})"
            parts.append(part)
        print(f"{name} rounds ({len(sel)}): " + "  ".join(parts))


if __name__ == "__main__":
    main()
