#!/usr/bin/python3
"""Writes small NIfTI seed files for fuzz/fuzz_nifti.cpp into the directory argv[1].

NIfTI-1 and NIfTI-2, plain and gzip, sform, qform only and no code, integer
with scaling and float data, 3-D and 4-D; each under the fuzzer's 4 KiB.
"""
import os
import sys

import numpy as np
import nibabel as nib

out = sys.argv[1]
rng = np.random.default_rng(5)
oblique = np.array([[1.2, 0.3, 0, -5], [-0.2, 1.1, 0.4, 3], [0, -0.3, 2.0, 7], [0, 0, 0, 1]])

img = nib.Nifti1Image((rng.uniform(size=(4, 3, 2)) > 0.5).astype(np.uint8), oblique, dtype=np.uint8)
nib.save(img, os.path.join(out, 'mask_uint8.nii'))
img = nib.Nifti1Image(rng.integers(-100, 100, (3, 3, 3)).astype(np.int16), oblique, dtype=np.int16)
img.header.set_slope_inter(0.01, 0.5)
nib.save(img, os.path.join(out, 'scaled_int16.nii'))
img = nib.Nifti1Image(rng.normal(size=(3, 2, 2, 2)).astype(np.float32), np.eye(4), dtype=np.float32)
img.set_sform(None, code=0)
img.set_qform(oblique, code=1)
nib.save(img, os.path.join(out, 'qform_4d.nii'))
img = nib.Nifti1Image(rng.normal(size=(3, 3, 3)).astype(np.float64), np.eye(4), dtype=np.float64)
img.set_sform(None, code=0)
img.set_qform(None, code=0)
nib.save(img, os.path.join(out, 'no_code_float64.nii'))
nib.save(nib.Nifti1Image(rng.integers(0, 9, (5, 5, 5)).astype(np.int32), oblique, dtype=np.int32),
         os.path.join(out, 'int32.nii.gz'))
nib.save(nib.Nifti2Image(rng.normal(size=(3, 3, 3)).astype(np.float32), oblique, dtype=np.float32),
         os.path.join(out, 'nifti2.nii'))
nib.save(nib.Nifti2Image(rng.integers(0, 2, (4, 4, 4)).astype(np.uint8), oblique, dtype=np.uint8),
         os.path.join(out, 'nifti2.nii.gz'))
