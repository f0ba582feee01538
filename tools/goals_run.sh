#!/usr/bin/env bash
# Every figure of the speed goals (issue 32) in one run, on one binary: single rays against
# rtcIntersect1 and tinybvh (../shared/perf/compare.sh), 8-ray packets against rtcIntersect8
# (compare_packets.sh), the editor's frame against Embree's e8 frame (compare_frame.sh) and
# the first coarse image (bench-progressive), with the CPU and the load average around each.
#
# usage: tools/goals_run.sh PATH/TO/tracelab [SIZE] [REPS]   (a release build with
#        --no-default-features is enough; ../shared beside the checkout)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tl=$(realpath "${1:?usage: goals_run.sh PATH/TO/tracelab [SIZE] [REPS]}")
size=${2:-800}
reps=${3:-7}
cd "$root"
date -u
grep -m1 "model name" /proc/cpuinfo
grep -m1 "^cpu family" /proc/cpuinfo
grep -m1 "^model\s" /proc/cpuinfo
grep -o -m1 -w "avx512f" /proc/cpuinfo || echo "no avx512f"
uptime
echo "== compare.sh"
../shared/perf/compare.sh "$tl" "$size" "$reps"
uptime
echo "== compare_packets.sh"
tools/compare_packets.sh "$tl" "$size" "$reps"
uptime
echo "== compare_frame.sh"
tools/compare_frame.sh "$tl" "$size" "$reps"
uptime
echo "== bench-progressive (first coarse image, 2 threads)"
for s in bench_bunny1k bench_bunny69k bench_cube bench_dragon871k; do
  echo "$s: $(cd ../shared/perf && "$tl" bench-progressive $s.txt --threads 2 --repeat "$reps" | tail -n 1)"
done
uptime
date -u
