#!/bin/sh
# Writes header.json texts into DIR as a seed corpus for fuzz_trxheader
# (its fixed directory: 2 streamlines, 5 points):
#   fuzz/seeds/trxheader.sh DIR
# The valid header, one with a shifted oblique affine, and near misses.
set -e
dir=${1:?usage: trxheader.sh DIR}
mkdir -p "$dir"
printf '{"DIMENSIONS": [10, 10, 10], "NB_STREAMLINES": 2, "NB_VERTICES": 5, "VOXEL_TO_RASMM": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}' > "$dir/valid.json"
printf '{"NB_STREAMLINES": 2, "NB_VERTICES": 5, "DIMENSIONS": [181, 217, 181],\n "VOXEL_TO_RASMM": [[0.9, 0.1, 0, -90.5], [-0.1, 0.9, 0, -126], [0, 0, 1.25, -72], [0, 0, 0, 1]]}\n' > "$dir/oblique.json"
printf '{"DIMENSIONS": [10, 10, 10], "NB_STREAMLINES": 3, "NB_VERTICES": 5, "VOXEL_TO_RASMM": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}' > "$dir/count.json"
printf '{"DIMENSIONS": [10, 10], "NB_STREAMLINES": 2, "NB_VERTICES": 5.0, "VOXEL_TO_RASMM": [[1, 0, 0], [0, 1, 0, 0]]}' > "$dir/shapes.json"
