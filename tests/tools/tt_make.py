#!/usr/bin/python3
"""DSI Studio TinyTrack (.tt.gz) test files, written with scipy's MAT-4 writer.

  tt_make.py OUTDIR

writes OUTDIR/<case>.tt.gz and OUTDIR/<case>.json for each case. The JSON
holds what a reader must produce: the streamlines in RAS+ mm, computed here
from the integer coordinates (in 1/32 voxel) with numpy as
trans_to_mni @ (v / 32 - 0.5), independently of the record bytes. Cases:
several track blocks ("track", "track1"), trans_to_mni stored 1 x 16
(row-major, as DSI Studio's memory) and 4 x 4 (MATLAB's column order), an
oblique affine, steps of the full int8 range, extra matrices the reader
must skip (report text, colour, cluster) placed before and between.
"""
import gzip
import io
import json
import sys

import numpy as np
import scipy.io as sio


def tract_bytes(coords):
    """One record: uint32 coordinate count, the first point (int32 x 3), int8 steps."""
    coords = np.asarray(coords, dtype=np.int64)
    steps = np.diff(coords, axis=0).ravel()
    assert np.all(steps >= -128) and np.all(steps <= 127)
    head = np.array([coords.size], '<u4').tobytes() + coords[0].astype('<i4').tobytes()
    return head + steps.astype('i1').tobytes()


def random_tract(rng, n, start):
    steps = rng.integers(-128, 128, (n - 1, 3))
    return np.vstack([start, start + np.cumsum(steps, axis=0)])


def write_case(outdir, name, blocks, affine, affine_shape, extra_first=True):
    mat = {}
    if extra_first:
        mat['report'] = 'A deterministic fiber tracking algorithm was used.'
        mat['color'] = np.array([[0xff8040]], dtype=np.float64)
    mat['dimension'] = np.array([[90, 108, 90]], dtype=np.float64)
    mat['voxel_size'] = np.array([[2.0, 2.0, 2.0]], dtype=np.float64)
    mat['trans_to_mni'] = (affine.reshape(1, 16) if affine_shape == '1x16' else affine).astype(np.float32)
    tracts = []
    for i, block in enumerate(blocks):
        data = b''.join(tract_bytes(t) for t in block)
        key = 'track' if i == 0 else 'track%d' % i
        mat[key] = np.frombuffer(data, dtype=np.uint8).reshape(-1, 1)
        if i == 0:
            mat['cluster'] = np.zeros((1, 3), dtype=np.uint16)  # a matrix between the blocks
        tracts.extend(block)
    raw = io.BytesIO()
    sio.savemat(raw, mat, format='4')
    with open('%s/%s.tt.gz' % (outdir, name), 'wb') as f:
        f.write(gzip.compress(raw.getvalue()))
    expected = []
    for t in tracts:
        v = np.asarray(t, dtype=np.float64) / 32.0 - 0.5
        world = (affine[:3, :3] @ v.T).T + affine[:3, 3]
        expected.append(world.astype(np.float32).ravel().tolist())
    with open('%s/%s.json' % (outdir, name), 'w') as f:
        json.dump({'streamlines': expected, 'affine': affine.ravel().tolist()}, f)


def main():
    outdir = sys.argv[1]
    rng = np.random.default_rng(11)
    mni = np.array([[-2, 0, 0, 90], [0, 2, 0, -126], [0, 0, 2, -72], [0, 0, 0, 1]], dtype=np.float64)
    c, s = np.cos(0.3), np.sin(0.3)
    oblique = np.array([[-1.5 * c, -1.5 * s, 0, 80.25], [1.5 * s, -1.5 * c, 0.1, 100.5],
                        [0, 0.2, 1.25, -60], [0, 0, 0, 1]], dtype=np.float64)
    first = [random_tract(rng, n, np.array([1440, 1728, 1440]) + rng.integers(-500, 500, 3))
             for n in (1, 2, 57, 300)]
    second = [random_tract(rng, n, np.array([1000, 2000, 900])) for n in (5, 1000)]
    write_case(outdir, 'mni_1x16', [first, second], mni, '1x16')
    write_case(outdir, 'oblique_4x4', [first], oblique, '4x4', extra_first=False)


if __name__ == '__main__':
    main()
