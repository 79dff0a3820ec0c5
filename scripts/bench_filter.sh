#!/usr/bin/env bash
# The fiber filter's speed, side by side in one run (this host's speed
# drifts by 20 % within minutes, so the tools alternate):
#   bench_filter.sh FILE.tck [RUNS]
# 1. `fibscope filter` against MRtrix3 `tckedit` with the same criteria
#    (two include spheres and an exclude sphere, then ends-only), each run
#    RUNS times alternately, both with their default threads; prints each
#    time, the medians, the ratio, and checks both kept the same streamlines
#    (same count; the tests check they are the same ones).
# 2. The GPU filter (select/gpu/gpu_fiber_filter.h) on the same file through
#    `fibscope bench`: the GPU time of one evaluation (what one changed
#    sphere costs: every region is re-tested) for the same criteria.
# The file: scripts/make_tckgen_250mb.sh OUT 17000 (279 MB, 23.2 M points).
set -euo pipefail
in=$1
runs=${2:-3}
fibscope=${FIBSCOPE:-$(dirname "$0")/../build/fibscope}
command -v tckedit >/dev/null || { echo "MRtrix3 (tckedit) not installed"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2)}'; }
seconds() { local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N); echo "$t1 - $t0" | bc -l; }

for variant in spheres ends-only; do
  if [ $variant = spheres ]; then
    ours=(--include sphere:-20,0,10,12 --include sphere:20,0,10,12 --exclude sphere:0,-40,0,10)
    theirs=(-include -20,0,10,12 -include 20,0,10,12 -exclude 0,-40,0,10)
  else
    ours=(--include sphere:0,0,40,25 --ends-only)
    theirs=(-include 0,0,40,25 -ends_only)
  fi
  : > "$tmp/ours"; : > "$tmp/theirs"
  for ((r = 0; r < runs; ++r)); do
    seconds tckedit -quiet -force "$in" "$tmp/t.tck" "${theirs[@]}" >> "$tmp/theirs"
    seconds "$fibscope" filter "$in" "$tmp/f.tck" --force "${ours[@]}" >> "$tmp/ours"
  done
  kept_t=$(tckinfo -quiet -count "$tmp/t.tck" 2>/dev/null | awk '/actual count/ {print $NF}')
  kept_f=$(tckinfo -quiet -count "$tmp/f.tck" 2>/dev/null | awk '/actual count/ {print $NF}')
  mt=$(median < "$tmp/theirs"); mf=$(median < "$tmp/ours")
  echo "$variant: tckedit $(tr '\n' ' ' < "$tmp/theirs")s (median $mt), fibscope filter $(tr '\n' ' ' < "$tmp/ours")s (median $mf): $(echo "$mt / $mf" | bc -l | cut -c1-5)x; kept $kept_t / $kept_f"
done

# The GPU filter: one evaluation's GPU time, per pipeline's input.
for pipeline in compute raw-compute; do
  "$fibscope" bench "$in" --frames 1 --warmup 0 --size 320x240 --pipeline $pipeline \
    --include sphere:-20,0,10,12 --include sphere:20,0,10,12 --exclude sphere:0,-40,0,10 --json > "$tmp/b.json"
  /usr/bin/python3 -c "import json; j = json.load(open('$tmp/b.json')); print('GPU filter ($pipeline input): kept', j['filter']['kept'], 'of', j['streamlines'], 'in', round(j['filter']['gpu_ms'], 1), 'ms on', j['device'])"
done
