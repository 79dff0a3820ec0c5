#!/usr/bin/env bash
# Makes a ~250 MB whole-brain-sized tractogram written by MRtrix3 tckgen, the
# input of the time-to-first-image benchmark (scripts/bench_first_image.sh):
#   make_tckgen_250mb.sh OUTDIR [COUNT]
# Writes OUTDIR/tckgen_250mb.tck (and the field it tracks: amp.nii, fod.mif,
# mask.nii, dirs.txt), then prints tckinfo and the file size.
#
# Same approach as tests/tools/mrtrix_fod_tractograms.sh (sharp lobes sampled
# on 60 directions, turned into lmax 8 FODs by amp2sh, tracked by tckgen), but
# on a brain-sized field: an ellipsoid of 140 x 170 x 120 mm in 2 mm voxels
# holding three crossing fibre families, so a whole-brain render has a
# brain's extent, density and all three direction colours:
#   - commissural arcs (left-right across the midline, curving up laterally),
#   - association arcs (anterior-posterior, strongest laterally),
#   - projection fans (inferior-superior from a "brainstem" point below),
# each voxel's lobes weighted by smooth functions of position.
# iFOD1 (MRtrix's probabilistic first-order tracker) at 0.1 mm steps, seeded
# uniformly in the mask, minimum length 20 mm, 2 threads. The default COUNT,
# 15000 streamlines (mean length ~135 mm), gave 246.2 MB and 20.5 M points in
# 24 s on a 2-core host. The RNG seed is fixed (MRTRIX_RNG_SEED), but with 2
# threads which streamlines are kept, and their order, depend on scheduling,
# so the size may differ slightly between runs.
# Exits 77 when MRtrix3 or nibabel is missing.
set -euo pipefail
out=$1
count=${2:-15000}
command -v tckgen >/dev/null || { echo "MRtrix3 (tckgen) not installed"; exit 77; }
/usr/bin/python3 -c 'import nibabel, numpy' 2>/dev/null || { echo "nibabel not installed"; exit 77; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$out"
/usr/bin/python3 - <<'PY'
import numpy as np, nibabel as nib
vs = 2.0
semi = np.array([70.0, 85.0, 60.0])          # ellipsoid semi-axes, mm (x: L-R, y: P-A, z: I-S)
dims = (2 * np.ceil(semi / vs) + 3).astype(int)
aff = np.diag([vs, vs, vs, 1.0]); aff[:3, 3] = -vs * (dims - 1) / 2
xyz = np.indices(dims).reshape(3, -1).T * vs + aff[:3, 3]
x, y, z = xyz.T
mask = ((xyz / semi) ** 2).sum(1) < 1

def unit(v):
    return v / (np.linalg.norm(v, axis=1, keepdims=True) + 1e-9)

# Commissural: circles around an A-P axis 40 mm below the centre, so fibres
# cross the midline horizontally and turn upward towards the sides.
t1 = unit(np.stack([z + 40, np.zeros_like(x), -x], 1))
w1 = np.exp(-(y / 55) ** 2)
# Association: circles around an L-R axis 60 mm below the centre.
t2 = unit(np.stack([np.zeros_like(x), z + 60, -y], 1))
w2 = np.clip(np.abs(x) / 40, 0.35, 1.0)
# Projection: rays from (0, -10, -100) mm, densest in two lateral columns.
t3 = unit(np.stack([x, y + 10, z + 100], 1))
w3 = 0.3 + 0.7 * np.exp(-((np.abs(x) - 25) / 15) ** 2)

g = np.random.default_rng(3).normal(size=(60, 3))
g /= np.linalg.norm(g, axis=1, keepdims=True)
amp = sum(w[:, None] * np.abs(t @ g.T) ** 16 for t, w in ((t1, w1), (t2, w2), (t3, w3)))
amp[~mask] = 0
# amp2sh -directions takes [azimuth elevation] pairs in radians.
np.savetxt('dirs.txt', np.c_[np.arctan2(g[:, 1], g[:, 0]), np.arccos(g[:, 2])])
nib.save(nib.Nifti1Image(amp.reshape(*dims, 60).astype(np.float32), aff), 'amp.nii')
nib.save(nib.Nifti1Image(mask.reshape(dims).astype(np.uint8), aff), 'mask.nii')
PY
amp2sh amp.nii fod.mif -directions dirs.txt -lmax 8 -force -quiet
export MRTRIX_RNG_SEED=7
start=$(date +%s.%N)
tckgen -algorithm iFOD1 fod.mif tckgen_250mb.tck -seed_image mask.nii -mask mask.nii -select "$count" \
  -step 0.1 -minlength 20 -nthreads 2 -force -quiet
end=$(date +%s.%N)
echo "tckgen: $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s"
tckinfo tckgen_250mb.tck -count
# Points from the layout: the header ends at the "file: . OFFSET" offset,
# then one float32 triplet per point, a NaN triplet after each streamline and
# an Inf triplet at the end.
/usr/bin/python3 - "$out/tckgen_250mb.tck" <<'PY'
import os, re, sys
path = sys.argv[1]
with open(path, 'rb') as f:
    head = f.read(65536).split(b'\nEND\n')[0].decode('latin-1')
offset = int(re.search(r'^file:\s*\.\s*(\d+)', head, re.M).group(1))
count = int(re.search(r'^count:\s*(\d+)', head, re.M).group(1))
size = os.path.getsize(path)
print(f'file: {path}')
print(f'size: {size} bytes ({size / 1e6:.1f} MB)')
print(f'streamlines: {count}')
print(f'points: {(size - offset) // 12 - count - 1}')
PY
