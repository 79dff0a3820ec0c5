#!/usr/bin/python3
"""Anatomical test images written by nibabel, with what nibabel reads from them.

  anatomy_make.py cases OUTDIR   small volumes for the slice tests; OUTDIR/cases.json
                                 holds, per case, the file, nibabel's img.affine,
                                 the shape, the values (x fastest) and, where the
                                 case has one, the bright voxel and its RAS
                                 position (affine @ voxel)
  anatomy_make.py head OUT.nii.gz  a T1-like head around the built-in phantom's
                                 140 x 170 x 120 mm brain ellipsoid (bright white
                                 matter, grey cortex with folds, dark CSF,
                                 ventricles and skull, bright scalp), 1.5 mm
"""
import json
import os
import sys

import numpy as np
import nibabel as nib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from nifti_make import affine, json_values  # noqa: E402


def centred(aff, shape):
    """`aff` moved so that the grid's centre lies at the world origin."""
    a = aff.copy()
    a[:3, 3] = -a[:3, :3] @ ((np.array(shape) - 1) / 2.0)
    return a


def cases(out):
    os.makedirs(out, exist_ok=True)
    found = {}

    def save(name, data, aff, bright=None):
        path = os.path.join(out, name + '.nii.gz')
        nib.save(nib.Nifti1Image(data.astype(np.float32), aff), path)
        img = nib.load(path)
        case = {'file': os.path.basename(path), 'affine': img.affine.tolist(), 'shape': list(img.shape),
                'values': json_values(img.get_fdata())}
        if bright is not None:
            case['bright_voxel'] = list(bright)
            case['bright_ras'] = (img.affine @ np.array(list(bright) + [1.0]))[:3].tolist()
        found[name] = case

    # One bright voxel in a dark volume: axis-aligned RAS, and an oblique,
    # permuted, flipped, anisotropic sform.
    shape = (20, 24, 18)
    ras = centred(affine((0, 0, 0), (2.0, 2.0, 2.0), (0, 0, 0)), shape)
    oblique = centred(affine((20, -10, 35), (1.8, 2.2, 2.0), (0, 0, 0), columns=(1, 0, 2), flips=(1, -1, 1)), shape)
    for name, aff, voxel in [('bright_ras', ras, (12, 9, 7)), ('bright_oblique', oblique, (7, 13, 10))]:
        data = np.zeros(shape)
        data[voxel] = 1000.0
        save(name, data, aff, voxel)

    # A smooth field (intensities at chosen pixels against nibabel's values).
    fshape = (16, 14, 12)
    i, j, k = np.indices(fshape).astype(np.float64)
    field = 500 + 300 * np.sin(0.5 * i) * np.cos(0.4 * j) + 20 * k
    save('field_ras', field, centred(affine((0, 0, 0), (3.0, 3.0, 3.0), (0, 0, 0)), fshape))
    save('field_oblique', field,
         centred(affine((-25, 15, 30), (2.5, 3.5, 3.0), (0, 0, 0), columns=(2, 0, 1), flips=(1, 1, -1)), fshape))

    # A flat slab of one value, for depth compositing against streamlines.
    flat_shape = (30, 30, 3)
    save('flat', np.full(flat_shape, 600.0), centred(affine((0, 0, 0), (2.0, 2.0, 2.0), (0, 0, 0)), flat_shape))

    with open(os.path.join(out, 'cases.json'), 'w') as f:
        json.dump(found, f)


def head(path):
    rng = np.random.default_rng(7)
    size = 1.5
    shape = (124, 148, 120)  # 186 x 222 x 180 mm
    aff = centred(affine((0, 0, 0), (size, size, size), (0, 0, 0)), shape)
    ijk = np.indices(shape).reshape(3, -1).T.astype(np.float64)
    xyz = ijk @ aff[:3, :3].T + aff[:3, 3]
    x, y, z = xyz.T
    az = np.arctan2(y, x)
    el = np.arctan2(z, np.hypot(x, y))
    brain = np.sqrt((x / 70) ** 2 + (y / 85) ** 2 + (z / 60) ** 2)
    skin = np.sqrt((x / 88) ** 2 + (y / 103) ** 2 + (z / 80) ** 2)
    # Gyri: the cortex's inner (white matter) boundary folds in and out.
    folds = 0.07 * np.sin(11 * az + 3 * np.sin(4 * el)) * np.cos(9 * el + 2 * np.cos(3 * az))
    v = np.zeros(len(x))
    v[skin <= 1.0] = 560.0                      # scalp (fat: bright in T1)
    v[skin <= 0.95] = 70.0                      # skull
    v[brain <= 1.06] = 140.0                    # CSF
    v[brain <= 1.0 + 0.3 * folds] = 430.0       # cortex (grey matter)
    v[brain <= 0.82 + folds] = 700.0            # white matter
    for sx in (-1, 1):
        thal = np.sqrt(((x - 11 * sx) / 9) ** 2 + ((y + 8) / 13) ** 2 + ((z - 2) / 9) ** 2)
        v[thal <= 1.0] = 520.0                  # thalamus (deep grey)
        vent = np.sqrt(((x - 7 * sx) / 5) ** 2 + ((y - 8) / 22) ** 2 + ((z - 14) / 8) ** 2)
        v[vent <= 1.0] = 150.0                  # lateral ventricles
    data = v.reshape(shape)
    # Partial volume: a [1 2 1] / 4 blur along each axis.
    for axis in range(3):
        data = 0.25 * np.roll(data, -1, axis) + 0.5 * data + 0.25 * np.roll(data, 1, axis)
    inside = skin.reshape(shape) <= 1.0
    data[inside] += rng.normal(0, 10, np.count_nonzero(inside))
    data[~inside] = np.abs(rng.normal(0, 8, np.count_nonzero(~inside)))  # air
    data = data.astype(np.float32)
    nib.save(nib.Nifti1Image(data, aff), path)


if __name__ == '__main__':
    if len(sys.argv) != 3 or sys.argv[1] not in ('cases', 'head'):
        sys.exit(__doc__)
    (cases if sys.argv[1] == 'cases' else head)(sys.argv[2])
