#!/usr/bin/env bash
# Like ../shared/perf/compare.sh, but for 8-ray packets: for each bench scene, tracelab's single
# rays, tracelab's `bench --packets` (4x2 tiles), and Embree (rtcIntersect1 and rtcIntersect8) on
# the same rays, 1 and 2 threads, in one run. Run compare.sh once first: it builds /tmp/embree_bench.
#
# usage: tools/compare_packets.sh PATH/TO/tracelab [SIZE] [REPS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
perf=$root/../shared/perf
tl=$(realpath "${1:?usage: compare_packets.sh PATH/TO/tracelab [SIZE] [REPS]}")
size=${2:-800}
reps=${3:-15}
eb=${EMBREE_BENCH:-/tmp/embree_bench}
[[ -x $eb ]] || { echo "no $eb: run ../shared/perf/compare.sh once first" >&2; exit 1; }
field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p" <<<"$2" | tail -n 1; }
printf '%-18s %3s %9s %9s %9s %9s %7s %7s %s\n' scene thr single packets e1 e8 'pk/e8' 'pk/e1' checksums
for scene in "$perf"/bench_*.txt; do
  name=$(basename "$scene" .txt)
  # the mesh, transform and camera, read back from the scene file as compare.sh does
  obj=$(sed -n 's/.*obj_file \.\.\/meshes\/\(.*\)/\1/p' "$scene")
  scale=$(sed -n 's/.*UniformScale \(.*\)/\1/p' "$scene")
  tr=$(sed -n 's/.*Translate \(.*\)/\1/p' "$scene")
  center=$(sed -n 's/.*center \(.*\)/\1/p' "$scene")
  dir=$(sed -n 's/.*direction \(.*\)/\1/p' "$scene" | head -n 1)
  eout=$(cd "$perf/../meshes" && "$eb" "$obj" --scale $scale --translate $tr --center $center \
         --direction $dir --up 0 1 0 --angle 30 --size "$size" "$size" --reps "$reps" 2>&1)
  for thr in 1 2; do
    s=$(cd "$perf" && "$tl" bench "$scene" --size "$size" "$size" --threads $thr --repeat "$reps" | tail -n 1)
    p=$(cd "$perf" && "$tl" bench "$scene" --size "$size" "$size" --threads $thr --repeat "$reps" --packets | tail -n 1)
    [[ $thr == 1 ]] && word="1 thread " || word="2 threads"
    e1=$(grep "rtcIntersect1  $word" <<<"$eout" | sed -n 's/.* \([0-9.]*\) Mrays.*/\1/p')
    e8=$(grep "rtcIntersect8  $word" <<<"$eout" | sed -n 's/.* \([0-9.]*\) Mrays.*/\1/p')
    same=DIFFER
    [[ $(field hits "$s") == $(field hits "$p") && $(field sum_t "$s") == $(field sum_t "$p") ]] && same=equal
    pm=$(field mrays_per_s "$p")
    printf '%-18s %3s %9s %9s %9s %9s %7.2f %7.2f %s\n' "$name" $thr "$(field mrays_per_s "$s")" "$pm" \
      "$e1" "$e8" "$(python3 -c "print($pm/$e8)")" "$(python3 -c "print($pm/$e1)")" $same
  done
done
