#!/usr/bin/env bash
# Issue 14's lent-GPU figure: one changed sphere re-evaluated by the GPU
# fiber filter at 1 M fibers / 0.86 G segments (the issue asks <= 10 ms).
# Each `bench` evaluates the filter once for its criteria (filter.gpu_ms:
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
in=$tmp/p$n.tck
[ -s "$in" ] || "$fibscope" phantom "$in" --streamlines "$n" --seed 1 --force | tail -1
# Fiblets once for the compute runs (each bench of the .tck would compress again).
[ -s "${in%.tck}.fbl" ] || "$fibscope" compress "$in" "${in%.tck}.fbl" --force | tail -1
"$fibscope" gpu-info | head -3 > "$out/device.txt" || true
specs=("--include sphere:-20,0,10,12"
       "--include sphere:-20,0,10,12 --include sphere:20,0,10,12 --exclude sphere:0,-40,0,10"
       "--include sphere:0,0,40,25 --ends-only"
       "--include box:-30,-20,0,30,20,20 --min-length 40")
for pipeline in compute raw-compute; do
  for i in "${!specs[@]}"; do
    # shellcheck disable=SC2086
    file=$in
    [ $pipeline = compute ] && file=${in%.tck}.fbl
    "$fibscope" bench "$file" --frames 2 --warmup 1 --size 1920x1080 --pipeline $pipeline ${specs[$i]} --json \
      > "$out/filter_${pipeline}_$i.json"
    python3 -c "import json,sys; j=json.load(open(sys.argv[1])); f=j['filter']; print(sys.argv[2], '|', sys.argv[3], '| kept', f['kept'], 'of', j['streamlines'], '|', round(f['gpu_ms'], 2), 'ms |', j['device'])" \
      "$out/filter_${pipeline}_$i.json" "$pipeline" "${specs[$i]}" | tee -a "$out/table.txt"
  done
done
