#!/usr/bin/env bash
# Makes real-tracker tractograms at 0.1 mm for the codec tests:
#   mrtrix_fod_tractograms.sh OUTDIR [COUNT]
# A synthetic fibre-orientation field (helices around the z axis in a hollow
# cylinder, as in mrtrix_tractogram.sh) is turned into FODs by MRtrix3's
# amp2sh (sharp lobes sampled on 60 directions, lmax 8); tckgen then tracks
# it with iFOD1 (probabilistic, the fiblets paper's main case) and SD_Stream
# (deterministic) at 0.1 mm, COUNT streamlines each (default 300), seeded in
# both directions from each seed as MRtrix does (so the two halves meet at
# the seed with a turn up to twice the angle limit). Single-threaded
# (-nthreads 0), so the output is the same on every run.
# Writes OUTDIR/ifod1.tck and OUTDIR/sdstream.tck. Exits 77 when MRtrix3 or
# nibabel is missing.
set -euo pipefail
out=$1
count=${2:-300}
command -v tckgen >/dev/null || { echo "MRtrix3 (tckgen) not installed"; exit 77; }
/usr/bin/python3 -c 'import nibabel, numpy' 2>/dev/null || { echo "nibabel not installed"; exit 77; }
mkdir -p "$out"
cd "$out"
/usr/bin/python3 - <<'PY'
import numpy as np, nibabel as nib
n, vs = 48, 2.0
aff = np.diag([vs, vs, vs, 1.0]); aff[:3, 3] = -vs * (n - 1) / 2
xyz = np.indices((n, n, n)).reshape(3, -1).T * vs + aff[:3, 3]
x, y, z = xyz.T
r = np.hypot(x, y)
d = np.stack([-y, x, 0.15 * r], 1)
d /= np.linalg.norm(d, axis=1, keepdims=True) + 1e-9
mask = (r > 15) & (r < 40) & (np.abs(z) < 30)
g = np.random.default_rng(3).normal(size=(60, 3))
g /= np.linalg.norm(g, axis=1, keepdims=True)
amp = np.abs(d @ g.T) ** 16
amp[~mask] = 0
# amp2sh -directions takes [azimuth elevation] pairs in radians.
np.savetxt('dirs.txt', np.c_[np.arctan2(g[:, 1], g[:, 0]), np.arccos(g[:, 2])])
nib.save(nib.Nifti1Image(amp.reshape(n, n, n, 60).astype(np.float32), aff), 'amp.nii')
nib.save(nib.Nifti1Image(mask.reshape(n, n, n).astype(np.uint8), aff), 'mask.nii')
PY
amp2sh amp.nii fod.mif -directions dirs.txt -lmax 8 -force -quiet
export MRTRIX_RNG_SEED=7
for algorithm in iFOD1 SD_Stream; do
  name=$(echo "$algorithm" | tr 'A-Z' 'a-z' | tr -d '_')
  tckgen -algorithm "$algorithm" fod.mif "$name.tck" -seed_image mask.nii -mask mask.nii -select "$count" \
    -step 0.1 -minlength 10 -nthreads 0 -force -quiet
done
