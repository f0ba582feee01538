#!/usr/bin/env bash
# The editor's frame against Embree, in one run: for each bench scene, `tracelab
# bench-progressive` (compile + coarse passes + full colour/normal/depth frame, 2 threads) with
# primary rays in packets and one at a time, and the time Embree's rtcIntersect8 takes for the
# same SIZE×SIZE primary rays on 2 threads (SIZE² / its Mrays/s). Run ../shared/perf/compare.sh
# once first: it builds /tmp/embree_bench.
#
# usage: tools/compare_frame.sh PATH/TO/tracelab [SIZE] [REPS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
perf=$root/../shared/perf
tl=$(realpath "${1:?usage: compare_frame.sh PATH/TO/tracelab [SIZE] [REPS]}")
size=${2:-800}
reps=${3:-15}
eb=${EMBREE_BENCH:-/tmp/embree_bench}
[[ -x $eb ]] || { echo "no $eb: run ../shared/perf/compare.sh once first" >&2; exit 1; }
field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p" <<<"$2" | tail -n 1; }
grep -m1 "model name" /proc/cpuinfo | sed 's/.*: /cpu: /'
printf '%-18s %10s %10s %10s %10s %10s %9s %9s\n' scene 'pk coarse' 'pk full' 'single full' 'pk/single' 'e8 frame' 'full/e8' 'single/e8'
for scene in "$perf"/bench_*.txt; do
  name=$(basename "$scene" .txt)
  obj=$(sed -n 's/.*obj_file \.\.\/meshes\/\(.*\)/\1/p' "$scene")
  scale=$(sed -n 's/.*UniformScale \(.*\)/\1/p' "$scene")
  tr=$(sed -n 's/.*Translate \(.*\)/\1/p' "$scene")
  center=$(sed -n 's/.*center \(.*\)/\1/p' "$scene")
  dir=$(sed -n 's/.*direction \(.*\)/\1/p' "$scene" | head -n 1)
  eout=$(cd "$perf/../meshes" && "$eb" "$obj" --scale $scale --translate $tr --center $center \
         --direction $dir --up 0 1 0 --angle 30 --size "$size" "$size" --reps "$reps" 2>&1)
  e8=$(grep "rtcIntersect8  2 threads" <<<"$eout" | sed -n 's/.* \([0-9.]*\) Mrays.*/\1/p')
  p=$(cd "$perf" && "$tl" bench-progressive "$scene" --size "$size" "$size" --threads 2 --repeat "$reps" | tail -n 1)
  s=$(cd "$perf" && "$tl" bench-progressive "$scene" --size "$size" "$size" --threads 2 --repeat "$reps" --single-rays | tail -n 1)
  pc=$(field coarse_ms "$p"); pf=$(field full_ms "$p"); sf=$(field full_ms "$s")
  python3 - "$name" "$pc" "$pf" "$sf" "$e8" "$size" <<'PY'
import sys
name, pc, pf, sf, e8, size = sys.argv[1], *map(float, sys.argv[2:6]), int(sys.argv[6])
ef = size * size / (e8 * 1e6) * 1e3
print(f"{name:<18} {pc:10.2f} {pf:10.2f} {sf:10.2f} {pf/sf:10.2f} {ef:10.2f} {pf/ef:9.2f} {sf/ef:9.2f}")
PY
done
