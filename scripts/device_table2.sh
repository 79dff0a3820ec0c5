#!/usr/bin/env bash
# Issue 18's lent-GPU run: the fiblets paper's tables 2 and 3 side by side,
# one `bench --compare` per set on the default (whole-brain) phantom,
# generated straight to .fbl (no .tck on disk, bounded memory), the paper's
# protocol (1920x1080, 1.14 degrees per frame, a full turn of 316 frames).
# Builds nothing on the device.
#
#   here:   scripts/device_prepare.sh build
#   device: . .gl/env.sh; scripts/device_table2.sh "$OUT" [paper|small]
#   try it here first: FIBSCOPE=build/fibscope scripts/device_table2.sh /tmp/t2 small
#
# Sets (paper): the paper's segment counts, 0.43 G at 0.1 mm (its 500 k
# iFOD1 fibers), 5.37 G at 0.05 mm (3 M) and 8.1 G at 0.1 mm (10 M); the
# phantom's mean fiber is 107 mm against the paper's 86, so the same
# segments take 404 k, 2.52 M and 7.61 M fibers. Every pipeline at 0.43 G,
# the fiblet pipelines only above (their raw vertices, 64 and 97 GB, are
# the paper's "—").
# small: 2 k and 5 k fibers, 8 frames, 640x360, for lavapipe.
# Writes OUT/<set>.json (bench's JSON), OUT/<set>.phantom.txt (the phantom's
# points/s and peak memory), OUT/device.txt and OUT/table.md.
# FRAMES and SAMPLE override the protocol (SAMPLE=N: bench --sample N).
set -euo pipefail
out=${1:?output folder}
scale=${2:-paper}
fibscope=${FIBSCOPE:-.gl/bin/fibscope}
mkdir -p "$out"
tmp=${TMPDIR:-/tmp}/device_table2
mkdir -p "$tmp"
"$fibscope" gpu-info > "$out/device.txt" 2>&1 || true

# Every pipeline the binary knows, with and without culling; the graphics
# ones (lines, geometry, tessellation, mesh) run on a datacentre GPU's few raster
# units, so they run slower there than on a desktop GPU of the same class.
all_variants() {
  local v=(compute/two-phase compute/frustum compute/none raw-compute lines)
  local help pipelines cullings
  help=$("$fibscope" bench --help 2>&1 || true)
  pipelines=$(grep -- '--pipeline TEXT' <<<"$help" | sed 's/.*one of: \([^;]*\);.*/\1/')
  cullings=$(grep -- '--culling TEXT' <<<"$help" | sed 's/.*one of: \([^;]*\);.*/\1/')
  # The mesh pipelines (VK_EXT_mesh_shader) only where gpu-info says the
  # device has them: bench refuses a --compare list naming them otherwise.
  local mesh=()
  grep -q '^mesh shaders: enabled' "$out/device.txt" &&
    mesh=(mesh/two-phase mesh/frustum mesh/none mesh-serial/two-phase mesh-serial/none)
  for extra in compute/coverage geometry/two-phase geometry/none tessellation/two-phase tessellation/none \
               "${mesh[@]}"; do
    # Only the pipelines and culling modes this build names in its help.
    local p=${extra%/*} c=${extra#*/}
    if grep -q -- "\(^\|, \)$p\(,\|$\)" <<<"$pipelines" && grep -q -- "\(^\|, \)$c\(,\|$\)" <<<"$cullings"; then
      v+=("$extra")
    fi
  done
  local IFS=,
  echo "${v[*]}"
}
fiblet_variants="compute/two-phase,compute/frustum,compute/none"

if [ "$scale" = small ]; then
  sets=("p2k 2000 0.1 all" "p5k 5000 0.1 fiblets")
  size=640x360
  frames=${FRAMES:-8}
  step=$(awk -v f="$frames" 'BEGIN { print 360 / f }')
else
  sets=("s0.43g 404000 0.1 all" "s5.37g 2520000 0.05 fiblets" "s8.1g 7610000 0.1 fiblets")
  size=1920x1080
  frames=${FRAMES:-316}
  step=1.14
fi
sample=()
[ -n "${SAMPLE:-}" ] && sample=(--sample "$SAMPLE")

echo "| set | segments | pipeline | mean ms | median ms | p95 ms | drawn |" > "$out/table.md"
echo "|---|---|---|---|---|---|---|" >> "$out/table.md"
for s in "${sets[@]}"; do
  read -r name n mm which <<<"$s"
  fbl=$tmp/$name.fbl
  if [ ! -s "$fbl" ]; then
    /usr/bin/time -v "$fibscope" phantom "$fbl" --streamlines "$n" --step "$mm" --seed 1 --force \
      > "$out/$name.phantom.txt" 2>&1
    grep -E "wrote|Maximum resident" "$out/$name.phantom.txt" || true
  fi
  variants=$fiblet_variants
  [ "$which" = all ] && variants=$(all_variants)
  "$fibscope" bench "$fbl" --size "$size" --frames "$frames" --step "$step" "${sample[@]}" \
    --compare "$variants" --json > "$out/$name.json"
  python3 - "$out/$name.json" "$name" >> "$out/table.md" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
for r in j["results"]:
    drawn = r.get("fiblets_drawn_fraction")
    print(f"| {sys.argv[2]} | {j['segments'] / 1e9:.3f} G | {r['pipeline']} | {r['mean_ms']:.2f} | "
          f"{r['median_ms']:.2f} | {r['p95_ms']:.2f} | {'-' if drawn is None else f'{100 * drawn:.1f} %'} |")
PY
done
cat "$out/table.md"
