#!/bin/sh
# Writes ROI-set JSON files into DIR as a seed corpus for fuzz_roiset:
#   fuzz/seeds/roiset.sh DIR
# Every key of the schema (select/roi_set.h) at least once, a minimal set,
# and sets one edit away from an error (a repeated key, a wrong type).
set -e
dir=${1:?usage: roiset.sh DIR}
mkdir -p "$dir"
printf '{"fibscope_roi_set": 1}' > "$dir/minimal.json"
cat > "$dir/full.json" <<'JSON'
{ "fibscope_roi_set": 1,
  "rois": [ { "name": "CST upper", "region": "sphere:1,2,3,4", "role": "include", "enabled": true },
            { "region": "box:-5,-5,-5,5,5,5", "role": "exclude" },
            { "name": "a", "region": "obox:0,0,0,1,2,3,10,20,30", "role": "include_ordered", "enabled": false },
            { "region": "mask:roi.nii.gz" } ],
  "ends_only": true,
  "min_length_mm": 20, "max_length_mm": 250.5,
  "scalar_ranges": [ { "name": "fa_mean", "component": 0, "min": 0.3, "max": 0.9, "enabled": true },
                     { "name": "curv", "component": 2, "max": 1e-3 } ],
  "clip_planes": [ { "point": [0, 0, 10], "normal": [0, 0, -1], "enabled": true },
                   { "point": [1.5, -2, 3], "normal": [1, 1, 0] } ],
  "slab": { "thickness_mm": 5, "follow": "axial" },
  "cut_meshes": [ { "mesh": "box:-10,-10,-10,10,10,10", "cull": "inside", "enabled": true },
                  { "mesh": "cut.obj", "cull": "outside" } ],
  "anatomy": "t1.nii.gz" }
JSON
printf '{"fibscope_roi_set": 1, "rois": [{"region": "sphere:0,0,0,1", "region": "sphere:0,0,0,2"}]}' > "$dir/repeated.json"
printf '{"fibscope_roi_set": 1, "clip_planes": [{"point": [0, 0], "normal": "up"}]}' > "$dir/types.json"
