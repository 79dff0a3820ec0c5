#!/bin/sh
# Writes spec texts into DIR as a seed corpus for fuzz_specs:
#   fuzz/seeds/specs.sh DIR
# The first byte picks the parser (fuzz_specs.cpp): 0 region, 1 clip plane,
# 2 slab, 3 cut mesh, 4 fiber scalar range.
set -e
dir=${1:?usage: specs.sh DIR}
mkdir -p "$dir"
printf '\000sphere:-12.5,3,40,6' > "$dir/sphere"
printf '\0001,2,3,4' > "$dir/sphere_bare"
printf '\000box:-10,-20,5,10,20,15.5' > "$dir/box"
printf '\000obox:0,0,0,10,20,30,15,-30,45' > "$dir/obox"
printf '\0010,0,10,0,0,-1' > "$dir/plane"
printf '\001-3.5,1e2,0,1,1,0' > "$dir/plane_oblique"
printf '\0025' > "$dir/slab"
printf '\0022.5:coronal' > "$dir/slab_follow"
printf '\003box:-5,-5,-5,5,5,5:inside' > "$dir/cut_box"
printf '\003sphere:0,0,0,20:outside' > "$dir/cut_sphere"
printf '\003obox:1,2,3,4,5,6,10,20,30:inside' > "$dir/cut_obox"
printf '\003./meshes/cortex.obj:outside' > "$dir/cut_obj"
printf '\004fa_mean:0.3:0.9' > "$dir/range"
printf '\004curv[2]::1e-3' > "$dir/range_component"
printf '\004a:b:0.1:' > "$dir/range_colon"
