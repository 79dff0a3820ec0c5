#!/usr/bin/env bash
# Issue 17's lent-GPU run: FiberVisualizer's tables 3 (time and memory
# against model size) and 4 (against kernel radius) with `fibscope bundle
# --report`, and the bundled models of its figures 7-8 (unbundled, R = 10,
# R = 20 voxels; isotropic and anisotropic) to render where the tests run.
#
#   here:   scripts/device_prepare.sh build
#   device: . .gl/env.sh; scripts/device_bundle.sh "$OUT" [paper|small]
#   try it here first: FIBSCOPE=build/fibscope scripts/device_bundle.sh /tmp/db small
#
# The paper's models hold 2.19-9.87 M points after resampling, its grid is
# 175 x 525 x 350 voxels (32.2 M). The phantom is resampled at the paper's
# default step (0.01 of the box's z extent: 1.165 mm, 93.3 samples a fiber
# on average), so 23.5 k-106 k fibers give those sizes; its box (with the
# kernel's margin, about 145 x 172 x 127 mm) is not the paper's shape, so
# the voxel is 0.46 mm: about 32.5 M voxels, the paper's count. Writes
# OUT/table.md, OUT/<row>.txt (each run's report) and OUT/figures/<name>.fbl
# (the figures' models, as fiblets: small enough to come back).
# TIMEOUT (seconds a run, default 120) bounds each run. Scales: paper (a
# lent GPU), lavapipe (the smallest model size and the radii on it, the
# paper's grid: minutes a row on a CPU device, no figures), small (a try).
set -euo pipefail
out=${1:?output folder}
scale=${2:-paper}
fibscope=${FIBSCOPE:-.gl/bin/fibscope}
limit=${TIMEOUT:-120}
mkdir -p "$out/figures"
tmp=${TMPDIR:-/tmp}/device_bundle
mkdir -p "$tmp"
voxel=0.46
# name fibers R mode
rows=("t3-2.19M 23480 10 isotropic" "t3-4.39M 47000 10 isotropic" "t3-9.87M 105800 10 isotropic"
      "t4-R6 105800 6 isotropic" "t4-R14 105800 14 isotropic" "an-2.19M-R10 23480 10 anisotropic")
figures=("iso-r10 10 isotropic" "iso-r20 20 isotropic" "aniso-r10 10 anisotropic" "aniso-r20 20 anisotropic")
figure_fibers=2000
if [ "$scale" = lavapipe ]; then
  rows=("t3-2.19M 23480 10 isotropic" "t4-R6 23480 6 isotropic" "t4-R14 23480 14 isotropic")
  figures=()
fi
if [ "$scale" = small ]; then
  voxel=2
  rows=("t3-small 500 5 isotropic" "t4-small 1000 3 isotropic" "an-small 500 3 anisotropic")
  figures=("iso-r3 3 isotropic" "aniso-r3 3 anisotropic")
  figure_fibers=300
fi

"$fibscope" gpu-info > "$out/device.txt" 2>&1 || true
echo "| row | fibers | mode | R (voxels) | report |" > "$out/table.md"
echo "|---|---|---|---|---|" >> "$out/table.md"
for r in "${rows[@]}"; do
  read -r name fibers radius mode <<<"$r"
  in=$tmp/p$fibers.fbl
  [ -s "$in" ] || "$fibscope" phantom "$in" --streamlines "$fibers" --seed 1 --force > /dev/null
  echo "bundle $name: $fibers fibers, R $radius, $mode" >&2
  if timeout "$limit" "$fibscope" bundle "$in" "$tmp/out.tck" --voxel "$voxel" --radius "$radius" --mode "$mode" \
      --report --force > "$out/$name.txt" 2>&1; then
    status=ok
  else
    status="failed or over ${limit} s (exit $?)"
  fi
  # The report's lines joined, so one row holds the run's figures.
  echo "| $name | $fibers | $mode | $radius | $status: $(grep -v 'warning:' "$out/$name.txt" | tr '\n' ' ' | tr '|' '/' | tr -s ' ' | cut -c1-1500) |" \
    >> "$out/table.md"
done

# Figures 7-8: the paper's voxel (0.003 of the box, the default) and radii.
fig_in=$tmp/p$figure_fibers.tck
[ ${#figures[@]} -eq 0 ] || [ -s "$fig_in" ] || "$fibscope" phantom "$fig_in" --streamlines "$figure_fibers" --seed 1 --force > /dev/null
for f in ${figures[@]+"${figures[@]}"}; do
  read -r name radius mode <<<"$f"
  echo "figure $name" >&2
  timeout "$limit" "$fibscope" bundle "$fig_in" "$out/figures/$name.fbl" --radius "$radius" --mode "$mode" \
    --report --force > "$out/figures/$name.txt" 2>&1 || echo "figure $name: failed or over $limit s" >&2
done
cat "$out/table.md"
