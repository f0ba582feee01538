#!/usr/bin/env bash
# Assignment 4's scenes through `bench-progressive` at 800x800 on 2 threads, each with its
# handout flags (the deepest -bounces line of a sequence) and three variants in the same run:
# primary rays only (no shadows, no bounces: the eye ray's Phong shading), shadows but no
# bounces, and the handout's flags with shadow rays asked by the closest hit instead of the
# any-hit query. Prints one table; docs/perf.md quotes it.
# Usage: tools/bench_a4.sh [TRACELAB] [SEMESTER_DIR]
set -euo pipefail
exe=${1:-target/release/tracelab}
dir=${2:-../shared/mit6837-semester}
exe=$(realpath "$exe")
cd "$dir/scenes"
run() { "$exe" bench-progressive "$1" --size 800 800 --threads 2 --repeat "${REPEAT:-5}" "${@:2}" |
  sed -n 's/^PROGRESSIVE coarse_ms=\([0-9.]*\) full_ms=\([0-9.]*\)$/\1 \2/p'; }
printf '%-44s %-34s %9s %9s %9s %9s %9s\n' scene "handout flags" coarse_ms full_ms primary shadows closest
# scene, then its handout flags in bench-progressive's spelling.
while read -r scene flags; do
  # shellcheck disable=SC2086
  read -r c f < <(run "$scene" $flags)
  read -r _ p < <(run "$scene" $( [[ $flags == *--shade-back* ]] && echo --shade-back))
  read -r _ s < <(run "$scene" --shadows $( [[ $flags == *--shade-back* ]] && echo --shade-back))
  # shellcheck disable=SC2086
  read -r _ k < <(run "$scene" $flags --closest-hit-shadows)
  printf '%-44s %-34s %9s %9s %9s %9s %9s\n' "$scene" "$flags" "$c" "$f" "$p" "$s" "$k"
done <<'LIST'
scene4_01_sphere_shadow.txt --shadows
scene4_02_colored_shadows.txt --shadows
scene4_03_mirrored_floor.txt --shadows --bounces 1 --weight 0.01
scene4_04_reflective_sphere.txt --shadows --bounces 3 --weight 0.01
scene4_05_transparent_bar.txt --shadows --bounces 10 --weight 0.01 --shade-back
scene4_06_transparent_bars.txt --shadows --bounces 5 --weight 0.01 --shade-back
scene4_07_transparent_sphere_1.0.txt --shadows --bounces 5 --weight 0.01 --shade-back
scene4_08_transparent_sphere_1.1.txt --shadows --bounces 5 --weight 0.01 --shade-back
scene4_09_transparent_sphere_2.0.txt --shadows --bounces 5 --weight 0.01 --shade-back
scene4_10_point_light_distance.txt --shadows
scene4_11_point_light_circle.txt --shadows
scene4_12_point_light_circle_d_attenuation.txt --shadows
scene4_13_point_light_circle_d2_attenuation.txt --shadows
scene4_14_faceted_gem.txt --shadows --shade-back --bounces 5 --weight 0.01
LIST
