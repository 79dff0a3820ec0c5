#!/usr/bin/env bash
# Issue 14's lent-GPU figure: one changed sphere re-evaluated by the GPU
# fiber filter at 1 M fibers / 0.86 G segments (the issue asks <= 10 ms).
# Each `bench` evaluates the filter for its criteria (filter.gpu_ms:
# every region re-tested, what one changed sphere costs) on the fiblets
# (compute pipeline's input) and on the raw vertices (the baselines').
#
#   here:   scripts/device_prepare.sh build
#   device: . .gl/env.sh; scripts/device_filter.sh "$OUT" [STREAMLINES]
#   try it here first: FIBSCOPE=build/fibscope scripts/device_filter.sh /tmp/df 2000
set -euo pipefail
out=${1:?output folder}
n=${2:-1000000}
fibscope=${FIBSCOPE:-.gl/bin/fibscope}
mkdir -p "$out"
tmp=${TMPDIR:-/tmp}/device_filter
mkdir -p "$tmp"
# Straight to fiblets (no .tck on disk): both pipelines read the .fbl, the
# raw-compute baseline its decoded vertices.
in=$tmp/p$n.fbl
[ -s "$in" ] || "$fibscope" phantom "$in" --streamlines "$n" --seed 1 --force | tail -1
"$fibscope" gpu-info | head -3 > "$out/device.txt" || true
specs=("--include sphere:-20,0,10,12"
       "--include sphere:-20,0,10,12 --include sphere:20,0,10,12 --exclude sphere:0,-40,0,10"
       "--include sphere:0,0,40,25 --ends-only"
       "--include box:-30,-20,0,30,20,20 --min-length 40")
# One bench a criteria set: the filter on the fiblets evaluated 9 times
# (median: what one changed sphere costs) and once on the raw vertices.
echo "| criteria | kept of fibers | fiblets: median GPU ms (each) | raw vertices: GPU ms | device |" > "$out/table.md"
echo "|---|---|---|---|---|" >> "$out/table.md"
for i in "${!specs[@]}"; do
  # shellcheck disable=SC2086
  "$fibscope" bench "$in" --frames 2 --warmup 1 --size 1920x1080 --compare compute/two-phase,raw-compute \
    --filter-evaluations 9 ${specs[$i]} --json > "$out/filter_$i.json"
  python3 -c "import json,sys; j=json.load(open(sys.argv[1])); f=j['filter']; print('|', sys.argv[2], '|', f['kept'], 'of', j['streamlines'], '|', round(f['gpu_ms'], 2), '(' + ', '.join(str(round(x, 2)) for x in f['gpu_ms_each']) + ') |', round(f.get('raw_gpu_ms', 0), 2), '|', j['device'], '|')" \
    "$out/filter_$i.json" "${specs[$i]}" | tee -a "$out/table.md"
done
