#!/usr/bin/env bash
# The spline-tube seed's figure 19 protocol (Salm, section 4): the camera
# orbiting the tubes at a fixed distance, 500 frames for a full turn, at
# 800x600 and 1200x768, far (the whole set in view) and close, every tube
# method side by side in one `bench --tube-compare` run per case, over the
# whole-brain phantom's lines. "none" is the same frames without tubes: on
# a CPU device (lavapipe), whose timestamps are not trusted, the tubes'
# cost is the wall time over it.
#
#   FIBSCOPE=build/fibscope scripts/tubes_figure19.sh OUT [small]
#
# Sets (the seed's counts in brackets; the phantom's fibers resampled
# within the tolerance to come near them): A 241 tubes (3,530 segments),
# B 1,701 (114,489), C 722 (30,948), D 10^5 fibers (the seed's largest
# bundle, --scale full only). small: sets A and C, 6 frames sampled from
# the orbit, for lavapipe; large: sets B and D, 2 frames sampled (on
# lavapipe a frame of B takes tens of seconds, tessellated D hours: D
# there without tess, METHODS_D). Writes OUT/<set>-<size>-<far|close>.json
# and OUT/table.md. FRAMES, SAMPLE, METHODS and METHODS_D override; SAMPLE_D
# samples set D alone (a lent GPU's time is counted), TIMEOUT (seconds)
# bounds each bench run (a case over it is left out of the table).
set -euo pipefail
out=${1:?output folder}
scale=${2:-full}
fibscope=${FIBSCOPE:-build/fibscope}
methods=${METHODS:-none,compute,raycast,tess}
frames=${FRAMES:-500}
sample=${SAMPLE:-0}
limit=${TIMEOUT:-0}
[ "$scale" = small ] && sample=${SAMPLE:-6}
[ "$scale" = large ] && sample=${SAMPLE:-2}
mkdir -p "$out"
"$fibscope" gpu-info > "$out/device.txt" 2>&1 || true
# A method this binary does not have is dropped (bench would refuse it).
have=()
IFS=, read -ra want <<<"$methods"
for m in "${want[@]}"; do
  if [ "$m" = none ] || "$fibscope" render --phantom-streamlines 20 --size 16x16 --tubes 0 --tube-method "$m" \
      -o "$out/.probe.png" >/dev/null 2>&1; then have+=("$m"); fi
done
methods=$(IFS=,; echo "${have[*]}")
methods_d=${METHODS_D:-$methods}
[ "$scale" = large ] && methods_d=${METHODS_D:-$(echo "$methods" | sed -e 's/,tess//' -e 's/^tess,//')}
rm -f "$out/.probe.png"

# name phantom-fibers tubes tolerance-mm radius-mm
sets=("A 2000 0-240 0.2 0.5" "C 2000 0-721 0.05 0.3" "B 2000 0-1700 0.027 0.3")
[ "$scale" = full ] && sets+=("D 100000 all 0.2 0.1")
[ "$scale" = small ] && sets=("A 2000 0-240 0.2 0.5" "C 2000 0-721 0.05 0.3")
[ "$scale" = large ] && sets=("B 2000 0-1700 0.027 0.3" "D 100000 all 0.2 0.1")
sizes=(800x600 1200x768)
for s in "${sets[@]}"; do
  read -r name fibers tubes tolerance radius <<<"$s"
  for size in "${sizes[@]}"; do
    for view in far close; do
      distance=1
      [ "$view" = close ] && distance=0.3
      json="$out/$name-$size-$view.json"
      these=$methods
      this_sample=$sample
      [ "$name" = D ] && these=$methods_d && this_sample=${SAMPLE_D:-$sample}
      echo "set $name ($tubes of $fibers fibers) $size $view: $these" >&2
      timeout "$limit" "$fibscope" bench --phantom-streamlines "$fibers" --tubes "$tubes" \
        --tube-tolerance "$tolerance" --tube-radius "$radius" --tube-compare "$these" --size "$size" \
        --distance "$distance" --frames "$frames" --step "$(python3 -c "print(360 / $frames)")" \
        --sample "$this_sample" --json > "$json.part" || { echo "  failed or over ${limit} s: left out" >&2; continue; }
      mv "$json.part" "$json"
    done
  done
done

python3 - "$out" <<'EOF'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
rows = ["| set | tubes | segments | tubes buffer MiB | size | view | method | method's buffers MiB | median wall ms | over none | tube passes median GPU ms |",
        "|---|---|---|---|---|---|---|---|---|---|---|"]
device = ""
for f in sorted(out.glob("*.json")):
    j = json.loads(f.read_text())
    device = j["device"] + ", " + j["driver"]
    name, size, view = f.stem.split("-")
    base = next((r["wall_median_ms"] for r in j["results"] if "tube_method" not in r), None)
    for r in j["results"]:
        method = r.get("tube_method", "none")
        over = "" if base is None or method == "none" else f"{r['wall_median_ms'] - base:.1f}"
        tube = f"{r['tube_median_ms']:.2f}" if "tube_median_ms" in r else ""
        own = f"{r['tube_method_bytes'] / 2**20:.2f}" if "tube_method_bytes" in r else ""
        rows.append(f"| {name} | {j['tubes']['fibers']} | {j['tubes']['segments']} | "
                    f"{j['tubes']['buffer_bytes'] / 2**20:.2f} | {size} | {view} | {method} | {own} | "
                    f"{r['wall_median_ms']:.1f} | {over} | {tube} |")
(out / "table.md").write_text(f"Device: {device}\n\n" + "\n".join(rows) + "\n")
print((out / "table.md").read_text())
EOF
