#!/usr/bin/env bash
# Makes a real MRtrix3 tractogram for interoperability tests:
#   mrtrix_tractogram.sh OUTDIR
# writes OUTDIR/fact.tck (tckgen, FACT on a synthetic helical direction
# field), OUTDIR/fact.vtk (tckconvert's VTK writer), OUTDIR/txt/s-NNNNNNN.txt
# (tckconvert's one-text-file-per-streamline output: the points as MRtrix
# prints them), OUTDIR/tckinfo.txt and OUTDIR/tckstats.txt.
# Exits 77 when MRtrix3 or nibabel is missing.
set -euo pipefail
out=$1
command -v tckgen >/dev/null || { echo "MRtrix3 (tckgen) not installed"; exit 77; }
/usr/bin/python3 -c 'import nibabel, numpy' 2>/dev/null || { echo "nibabel not installed"; exit 77; }
mkdir -p "$out/txt"
cd "$out"
/usr/bin/python3 - <<'PY'
import numpy as np, nibabel as nib
# A 48^3 grid of 2 mm voxels; directions follow helices around the z axis
# inside a hollow cylinder, so FACT tracks long smooth curved streamlines.
n, vs = 48, 2.0
aff = np.diag([vs, vs, vs, 1.0]); aff[:3, 3] = -vs * (n - 1) / 2
xyz = np.indices((n, n, n)).reshape(3, -1).T * vs + aff[:3, 3]
x, y, z = xyz.T
r = np.hypot(x, y)
d = np.stack([-y, x, 0.15 * r], 1)
d /= np.linalg.norm(d, axis=1, keepdims=True) + 1e-9
mask = ((r > 15) & (r < 40) & (np.abs(z) < 30)).astype(np.uint8)
d[mask == 0] = 0
nib.save(nib.Nifti1Image(d.reshape(n, n, n, 3).astype(np.float32), aff), 'peaks.nii')
nib.save(nib.Nifti1Image(mask.reshape(n, n, n), aff), 'mask.nii')
PY
export MRTRIX_RNG_SEED=7
tckgen -algorithm FACT peaks.nii fact.tck -seed_image mask.nii -mask mask.nii -select 300 -step 0.5 \
  -angle 30 -minlength 10 -nthreads 0 -force -quiet
tckconvert fact.tck fact.vtk -force -quiet
tckconvert fact.tck 'txt/s-[].txt' -force -quiet
tckinfo fact.tck -count > tckinfo.txt
tckstats fact.tck -quiet > tckstats.txt
