#!/usr/bin/env bash
# The SVO seed's table 1 (McGraw: memory of the streamline buffer, the
# octree and its decoration per bundle) on phantom bundles sized to the
# seed's streamline buffers, plus a whole-brain set of about 19.5 M
# vertices, with the voxelisation, sort and tree times of each build.
#
#   FIBSCOPE=build/fibscope scripts/svo_table1.sh OUT [small|full]
#
# The seed's bundles have no phantom counterpart by name; each is made
# from the phantom bundle of a like shape alone (--mix bundles, one bundle
# weight 1) with as many fibers as bring the tube model's streamline
# buffer (the TubeNode and TubeSegment records the tracer reads: 48 + 16
# bytes per point at the svo pipelines' tolerance 0) to the seed's size:
#   CP 0.417 MB -> cst_left, SCP R 1.67 -> cst_right, SLF R 16.2 ->
#   arcuate_right, Cingulum L 24.9 -> cingulum_left, MCP 38.7 ->
#   corpus_callosum.
# Fibers at STEP mm (0.5), tubes of RADIUS mm (0.5), the voxel by the rule
# (VOXEL overrides; the whole brain's is coarsened by the density criterion
# until the octree fits the device). small: the first two bundles and no
# whole brain. Writes OUT/<name>.log (render's summary) and OUT/table.md;
# KEEP=1 keeps the sets' .tck files (for GpuSvoTrace.table2WhenAsked).
set -euo pipefail
out=${1:?output folder}
scale=${2:-full}
fibscope=${FIBSCOPE:-build/fibscope}
step=${STEP:-0.5}
radius=${RADIUS:-0.5}
voxel=${VOXEL:-}
wb_points=${WB_POINTS:-19500000}
mkdir -p "$out"
"$fibscope" gpu-info > "$out/device.txt" 2>&1 || true

bundles="corpus_callosum cst_left cst_right arcuate_left arcuate_right cingulum_left cingulum_right ifof_left ifof_right ilf_left ilf_right u_fibers"
only() {  # --bundles text with weight 1 for $1 and 0 for the other named bundles
  local mix=""
  for b in $bundles; do mix+="$b=$([ "$b" = "$1" ] && echo 1 || echo 0),"; done
  echo "${mix%,}"
}
points_of() { sed -n 's/.*streamlines, \([0-9]*\) points.*/\1/p' "$1"; }

# name phantom-bundle target-MB
sets=("CP cst_left 0.417" "SCP_R cst_right 1.67" "SLF_R arcuate_right 16.2" "Cingulum_L cingulum_left 24.9"
      "MCP corpus_callosum 38.7")
[ "$scale" = small ] && sets=("${sets[@]:0:2}")
run() {  # name file
  local args=(render "$2" --pipeline svo-straight --tube-radius "$radius" --size 320x240 -o "$out/$1.png")
  [ -n "$voxel" ] && args+=(--voxel "$voxel")
  echo "$1: ${args[*]}" >&2
  /usr/bin/time -f "wall %e s, peak %M KB" "$fibscope" "${args[@]}" > "$out/$1.log" 2>&1 || { cat "$out/$1.log" >&2; true; }
}
for s in "${sets[@]}"; do
  read -r name bundle target <<<"$s"
  # Calibrate the points per fiber on 200 fibers, then make the set.
  "$fibscope" phantom -n 200 --step "$step" --mix bundles --bundles "$(only "$bundle")" "$out/.calib.tck" -f \
    > "$out/.calib.log" 2>&1
  fibers=$(python3 -c "print(max(1, round($target * 1e6 / 64 / ($(points_of "$out/.calib.log") / 200))))")
  "$fibscope" phantom -n "$fibers" --step "$step" --mix bundles --bundles "$(only "$bundle")" "$out/$name.tck" -f \
    > "$out/$name.phantom.log" 2>&1
  run "$name" "$out/$name.tck"
  [ "${KEEP:-0}" = 1 ] || rm -f "$out/$name.tck"
done
if [ "$scale" = full ]; then
  "$fibscope" phantom -n 1000 --step "$step" "$out/.calib.tck" -f > "$out/.calib.log" 2>&1
  fibers=$(python3 -c "print(round($wb_points / ($(points_of "$out/.calib.log") / 1000)))")
  "$fibscope" phantom -n "$fibers" --step "$step" "$out/whole_brain.tck" -f > "$out/whole_brain.phantom.log" 2>&1
  run whole_brain "$out/whole_brain.tck"
  [ "${KEEP:-0}" = 1 ] || rm -f "$out/whole_brain.tck"
fi
rm -f "$out/.calib.tck" "$out/.calib.log"

python3 - "$out" <<'EOF'
import pathlib, re, sys
out = pathlib.Path(sys.argv[1])
seed = {"CP": 0.417, "SCP_R": 1.67, "SLF_R": 16.2, "Cingulum_L": 24.9, "MCP": 38.7, "whole_brain": None}
rows = ["| set | fibers | points | streamline buffer MB (seed's) | voxel mm | grid | leaves | leaves > 4 segments "
        "| nodes MB | decoration MB | octree total MB | voxelise s | sort s | build s | render wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for name in seed:
    log = out / f"{name}.log"
    if not log.exists():
        continue
    text = log.read_text()
    ph = re.search(r"(\d+) streamlines, (\d+) points", (out / f"{name}.phantom.log").read_text())
    m = re.search(r"streamline buffer ([\d.]+) MB\), voxel ([\d.]+) mm, (\d+)\^3 grid.*?, (\d+) leaves \((\d+) with "
                  r"more than 4.*?nodes ([\d.]+) MB, decoration ([\d.]+) MB(?:, lod [\d.]+ MB)?; voxelise ([\d.]+) s, "
                  r"sort ([\d.]+) s, build ([\d.]+) s", text)
    wall = re.search(r"wall ([\d.]+) s", text)
    if not m:
        err = next((l for l in text.splitlines() if "error" in l), "no summary")
        rows.append(f"| {name} | {ph.group(1)} | {ph.group(2)} | | | | {err} | | | | | | | | |")
        continue
    buf, vox, side, leaves, over4, nodes, deco, vs, ss, bs = m.groups()
    ref = f" ({seed[name]})" if seed[name] else ""
    rows.append(f"| {name} | {int(ph.group(1)):,} | {int(ph.group(2)):,} | {buf}{ref} | {vox} | {side}^3 | "
                f"{int(leaves):,} | {int(over4):,} | {nodes} | {deco} | {float(nodes) + float(deco):.3f} | {vs} | {ss} | "
                f"{bs} | {wall.group(1) if wall else ''} |")
(out / "table.md").write_text("\n".join(rows) + "\n")
print("\n".join(rows))
EOF
