#!/usr/bin/python3
"""Reference TrackVis files and values from nibabel, for fibscope's trk tests.

  trk_reference.py make OUTDIR      writes test .trk files into OUTDIR, each
                                    with OUTDIR/<name>.json holding what
                                    nibabel reads from it
  trk_reference.py dump FILE JSON   writes what nibabel reads from FILE

The JSON holds RAS+ mm streamlines (nibabel's tractogram.streamlines), the
data arrays (name -> list per streamline of flat component lists), nibabel's
voxmm->RAS affine and a few header fields. float32 values are exact in JSON
(Python floats are doubles).
"""
import json
import sys

import numpy as np
import nibabel as nib
from nibabel.streamlines import Field
from nibabel.streamlines.trk import TrkFile, get_affine_trackvis_to_rasmm, header_2_dtype


def affine(rotation_deg, axis_sizes, translation, flips=(1, 1, 1), permutation=(0, 1, 2)):
    """A vox->RAS affine: permuted/flipped axes, anisotropic voxels, a rotation about z."""
    t = np.radians(rotation_deg)
    rot = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])
    perm = np.eye(3)[list(permutation)].T * np.array(flips)
    a = np.eye(4)
    a[:3, :3] = rot @ perm @ np.diag(axis_sizes)
    a[:3, 3] = translation
    return a.astype(np.float32)


def streamlines_in(center, count, seed, extent=30.0):
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        n = 1 if i == 3 else int(rng.integers(2, 40))
        start = np.asarray(center) + rng.uniform(-extent, extent, 3)
        steps = rng.normal(0, 1, (n, 3)) * 0.8 + rng.normal(0, 1, 3)
        out.append((start + np.cumsum(steps, axis=0)).astype(np.float32))
    return out


def make_tractogram(streamlines, seed, with_data=True):
    rng = np.random.default_rng(seed + 1000)
    t = nib.streamlines.Tractogram(streamlines, affine_to_rasmm=np.eye(4))
    if with_data:
        t.data_per_point['fa'] = [rng.uniform(0, 1, (len(s), 1)).astype(np.float32) for s in streamlines]
        t.data_per_point['rgb'] = [rng.uniform(0, 255, (len(s), 3)).astype(np.float32) for s in streamlines]
        t.data_per_streamline['weight'] = rng.uniform(0, 2, (len(streamlines), 1)).astype(np.float32)
        t.data_per_streamline['pair'] = rng.normal(0, 5, (len(streamlines), 2)).astype(np.float32)
    return t


def save(path, tractogram, vox_to_ras, voxel_sizes, dims, order):
    header = {
        Field.VOXEL_TO_RASMM: vox_to_ras,
        Field.VOXEL_SIZES: np.array(voxel_sizes, dtype=np.float32),
        Field.DIMENSIONS: np.array(dims, dtype=np.int16),
        Field.VOXEL_ORDER: order,
    }
    TrkFile(tractogram, header=header).save(path)


def dump(path, json_path):
    trk = nib.streamlines.load(path)
    t = trk.tractogram
    h = trk.header
    out = {
        'streamlines': [np.asarray(s, dtype=np.float64).ravel().tolist() for s in t.streamlines],
        'data_per_point': {k: [np.asarray(v, dtype=np.float64).ravel().tolist() for v in seq]
                           for k, seq in t.data_per_point.items()},
        'data_per_streamline': {k: np.asarray(v, dtype=np.float64).tolist()
                                for k, v in t.data_per_streamline.items()},
        'affine': np.asarray(get_affine_trackvis_to_rasmm(h), dtype=np.float64).ravel().tolist(),
        'vox_to_ras': np.asarray(h[Field.VOXEL_TO_RASMM], dtype=np.float64).ravel().tolist(),
        'dimensions': [int(v) for v in h[Field.DIMENSIONS]],
        'voxel_sizes': [float(v) for v in h[Field.VOXEL_SIZES]],
        'voxel_order': h[Field.VOXEL_ORDER].decode('latin1') if isinstance(h[Field.VOXEL_ORDER], bytes)
        else str(h[Field.VOXEL_ORDER]),
        'n_count': int(h[Field.NB_STREAMLINES]),
    }
    with open(json_path, 'w') as f:
        json.dump(out, f)


def byte_swapped(path, out_path):
    """The same file in big-endian byte order (nibabel only writes little-endian)."""
    raw = open(path, 'rb').read()
    hdr = np.frombuffer(raw[:1000], dtype=header_2_dtype)
    swapped_hdr = hdr.astype(header_2_dtype.newbyteorder('>'))
    # Everything after the header is int32 counts and float32 values: 4-byte words.
    body = np.frombuffer(raw[1000:], dtype='<u4').astype('>u4')
    with open(out_path, 'wb') as f:
        f.write(swapped_hdr.tobytes())
        f.write(body.tobytes())


def as_version1(path, out_path):
    """A version-1 header: no vox_to_ras (that space is reserved, zero)."""
    hdr = np.frombuffer(open(path, 'rb').read()[:1000], dtype=header_2_dtype).copy()
    raw = open(path, 'rb').read()
    hdr['version'] = 1
    hdr[Field.VOXEL_TO_RASMM] = 0
    with open(out_path, 'wb') as f:
        f.write(hdr.tobytes())
        f.write(raw[1000:])


def make(outdir):
    cases = []
    # Oblique affine with anisotropic voxels; header voxel order LPS differs
    # from the affine's (RAS), so nibabel re-orients with the dimensions.
    a1 = affine(20.0, (2.0, 1.5, 3.0), (-40.0, 12.5, 7.25))
    s1 = streamlines_in((0, 0, 0), 24, seed=1)
    save(f'{outdir}/oblique_lps.trk', make_tractogram(s1, 1), a1, (2.0, 1.5, 3.0), (64, 80, 40), b'LPS')
    cases.append('oblique_lps')
    # Permuted, flipped axes (affine order ASL-like) with lower-case voxel order.
    a2 = affine(0.0, (1.25, 2.5, 0.8), (90.0, -120.0, -60.0), flips=(-1, 1, -1), permutation=(1, 2, 0))
    s2 = streamlines_in((10, -5, 3), 18, seed=2)
    save(f'{outdir}/permuted_las.trk', make_tractogram(s2, 2), a2, (1.25, 2.5, 0.8), (96, 96, 60), b'las')
    cases.append('permuted_las')
    # Identity grid, RAS, no data arrays, negative coordinates.
    s3 = streamlines_in((-20, 30, -10), 12, seed=3)
    save(f'{outdir}/identity_ras.trk', make_tractogram(s3, 3, with_data=False), np.eye(4, dtype=np.float32),
         (1.0, 1.0, 1.0), (100, 100, 100), b'RAS')
    cases.append('identity_ras')
    byte_swapped(f'{outdir}/oblique_lps.trk', f'{outdir}/oblique_lps_big.trk')
    cases.append('oblique_lps_big')
    as_version1(f'{outdir}/oblique_lps.trk', f'{outdir}/oblique_lps_v1.trk')
    cases.append('oblique_lps_v1')
    for name in cases:
        dump(f'{outdir}/{name}.trk', f'{outdir}/{name}.json')


if __name__ == '__main__':
    import warnings
    warnings.simplefilter('ignore')
    if len(sys.argv) == 3 and sys.argv[1] == 'make':
        make(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == 'dump':
        dump(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
