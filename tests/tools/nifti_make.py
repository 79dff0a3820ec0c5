#!/usr/bin/python3
"""NIfTI test images written by nibabel, with what nibabel reads from them.

  nifti_make.py volumes OUTDIR   small volumes of every datatype and header
                                 variant; OUTDIR/cases.json holds, per case,
                                 the file, nibabel's img.affine, the shape,
                                 the volume count and the first volume's
                                 values (x fastest)
  nifti_make.py masks OUTDIR     masks over the synthetic field of
                                 mrtrix_fod_tractograms.sh (fibres winding
                                 about z at radius 15-40 mm, |z| < 30 mm), and
                                 per mask a .tck of two-point streamlines
                                 sitting on the faces between its set and unset
                                 voxels (and the image's outer faces), each
                                 point a few float32 ulps from the face

Values in JSON: float32 values as Python floats (exact), non-finite ones as
the strings "nan", "inf", "-inf". "mask" is what MRtrix3 reads as true when it
opens the image as a mask: a finite value with |value| >= 0.5 (it rounds half
away from zero to a bool).
"""
import gzip
import json
import os
import sys

import numpy as np
import nibabel as nib


def rotation(ax, ay, az):
    """Rz(az) Ry(ay) Rx(ax), degrees."""
    x, y, z = np.radians([ax, ay, az])
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    return rz @ ry @ rx


def affine(angles, sizes, translation, columns=(0, 1, 2), flips=(1, 1, 1)):
    """Voxel axes: the world axes `columns` (permuted), flipped, scaled, rotated."""
    a = np.eye(4)
    axes = np.eye(3)[:, list(columns)] * np.array(flips, dtype=float)
    a[:3, :3] = rotation(*angles) @ axes @ np.diag(sizes)
    a[:3, 3] = translation
    return a


def json_values(array):
    out = []
    for v in np.asarray(array, dtype=np.float64).ravel(order='F'):
        with np.errstate(over='ignore'):
            v32 = np.float32(v)  # float64's max becomes inf, as in fibscope's float values
        out.append(float(v32) if np.isfinite(v32) else ('nan' if np.isnan(v32) else ('inf' if v32 > 0 else '-inf')))
    return out


def mrtrix_mask(values):
    v = np.asarray(values, dtype=np.float64)
    with np.errstate(invalid='ignore'):
        return (np.isfinite(v) & (np.abs(v) >= 0.5)).astype(np.float64)


def record(cases, name, path):
    img = nib.load(path)
    data = img.get_fdata(dtype=np.float64)  # stored * slope + inter, as nibabel scales
    shape = list(data.shape)
    first = data if data.ndim <= 3 else data.reshape(data.shape[:3] + (-1,), order='F')[..., 0]
    h = img.header
    cases[name] = {
        'file': os.path.basename(path),
        'affine': img.affine.tolist(),
        'shape': shape,
        'volumes': int(np.prod(shape[3:])) if len(shape) > 3 else 1,
        'values': json_values(first),
        'mask': json_values(mrtrix_mask(first)),
        'sform_code': int(h['sform_code']),
        'qform_code': int(h['qform_code']),
        'version': 2 if isinstance(img, (nib.Nifti2Image, nib.Nifti2Pair)) else 1,
        # get_zooms() for the axes there are; pixdim[1..3] (nibabel's, after
        # its load-time fixes) for all three.
        'zooms': [float(z) for z in h.get_zooms()[:3]],
        'pixdim': [float(abs(z)) for z in h['pixdim'][1:4]],
    }


def volumes(out):
    rng = np.random.default_rng(14)
    cases = {}
    shape = (5, 4, 3)
    base = affine((0, 0, 0), (2.0, 2.5, 3.0), (-4.0, -3.5, 7.25))

    def save(name, img, ext='.nii'):
        path = os.path.join(out, name + ext)
        nib.save(img, path)
        record(cases, name, path)

    # Every datatype, with its extremes (int64 and uint64 beyond 2^53: the
    # conversion to double rounds).
    for dt in ['uint8', 'int8', 'int16', 'uint16', 'int32', 'uint32', 'int64', 'uint64', 'float32', 'float64']:
        if dt.startswith('float'):
            data = rng.normal(0, 100, shape).astype(dt)
            data.flat[0] = np.finfo(dt).max
            data.flat[1] = -np.finfo(dt).tiny
        else:
            info = np.iinfo(dt)
            data = rng.integers(info.min, info.max, shape, dtype=dt, endpoint=True)
            data.flat[0], data.flat[1] = info.min, info.max
        if dt in ('int64', 'uint64'):
            data.flat[2] = np.array(2**53 + 1, dtype=dt)
        img = nib.Nifti1Image(data, base, dtype=dt)
        img.header.set_slope_inter(1.0, 0.0)
        save('dt_' + dt, img)

    # Scaling: nibabel's stored * slope + inter (float64); slope 0 or NaN:
    # none at all, whatever scl_inter says.
    ints = rng.integers(-3000, 3000, shape).astype(np.int16)
    for name, slope, inter in [('scaled_int16', 0.37, -12.5), ('slope_zero', 0.0, 5.0), ('slope_nan', np.nan, 5.0)]:
        img = nib.Nifti1Image(ints, base, dtype=np.int16)
        img.header['scl_slope'] = slope
        img.header['scl_inter'] = inter
        path = os.path.join(out, name + '.nii')
        img.to_filename(path)
        # to_filename leaves a set slope alone; write the fields as asked.
        raw = bytearray(open(path, 'rb').read())
        raw[112:116] = np.float32(slope).tobytes()
        raw[116:120] = np.float32(inter).tobytes()
        open(path, 'wb').write(bytes(raw))
        record(cases, name, path)
    floats = rng.normal(0, 1, shape).astype(np.float32)
    img = nib.Nifti1Image(floats, base, dtype=np.float32)
    path = os.path.join(out, 'scaled_float32.nii')
    img.to_filename(path)
    raw = bytearray(open(path, 'rb').read())
    raw[112:116] = np.float32(2.5).tobytes()
    raw[116:120] = np.float32(-0.75).tobytes()
    open(path, 'wb').write(bytes(raw))
    record(cases, 'scaled_float32', path)

    # Non-finite values: min/max are of the finite ones; a NaN is no mask.
    special = rng.normal(0, 1, shape).astype(np.float32)
    xfast = special.T.flat  # voxel 3 of x-fastest order is xfast[3]
    xfast[3], xfast[4], xfast[5] = np.nan, np.inf, -np.inf
    xfast[6], xfast[7], xfast[8], xfast[9] = 0.5, -0.5, 0.49999997, -0.49999997
    save('nonfinite_float32', nib.Nifti1Image(special, base, dtype=np.float32))

    # Orientation: an oblique, permuted, flipped sform with a different
    # qform (nibabel takes the sform); qform only (with qfac -1); no code.
    oblique = affine((20, -10, 35), (1.3, 0.9, 1.7), (-11.3, -7.7, -13.1), columns=(1, 0, 2), flips=(1, -1, 1))
    img = nib.Nifti1Image(floats, oblique, dtype=np.float32)
    img.set_qform(affine((0, 0, 10), (1, 1, 1), (1, 2, 3)), code=1)
    img.set_sform(oblique, code=2)
    save('oblique_sform', img)
    qform = affine((15, 25, -40), (1.5, 2.0, 2.5), (10.0, -20.0, 30.0), flips=(1, 1, -1))
    img = nib.Nifti1Image(floats, qform, dtype=np.float32)
    img.set_sform(None, code=0)
    img.set_qform(qform, code=1)
    save('qform_only', img)
    img = nib.Nifti1Image(floats, base, dtype=np.float32)
    img.set_sform(None, code=0)
    img.set_qform(None, code=0)
    save('no_codes', img)

    # Containers: gzip, NIfTI-2 (plain and gzip), a .hdr/.img pair, big-endian,
    # 4-D (the first volume is read), 2-D.
    save('gzipped', nib.Nifti1Image(ints, oblique, dtype=np.int16), '.nii.gz')
    wide = rng.normal(0, 1, shape)
    save('nifti2', nib.Nifti2Image(wide, oblique, dtype=np.float64))
    save('nifti2_gz', nib.Nifti2Image(ints, qform, dtype=np.int16), '.nii.gz')
    save('pair', nib.Nifti1Pair(ints, oblique, dtype=np.int16), '.hdr')
    header = nib.Nifti1Header(endianness='>')
    save('big_endian', nib.Nifti1Image(ints.astype('>i2'), oblique, header=header, dtype=np.dtype('>i2')))
    four = rng.normal(0, 1, shape + (3,)).astype(np.float32)
    save('four_d', nib.Nifti1Image(four, oblique, dtype=np.float32))
    save('four_d_gz', nib.Nifti1Image(four, oblique, dtype=np.float32), '.nii.gz')
    save('two_d', nib.Nifti1Image(floats[:, :, 0], base, dtype=np.float32))

    with open(os.path.join(out, 'cases.json'), 'w') as f:
        json.dump(cases, f)


# --- masks for the tractograms of mrtrix_fod_tractograms.sh ------------------

def write_tck(path, streamlines):
    body = b''.join(np.asarray(s, '<f4').tobytes() + np.full(3, np.nan, '<f4').tobytes() for s in streamlines)
    body += np.full(3, np.inf, '<f4').tobytes()
    head = 'mrtrix tracks\ndatatype: Float32LE\ncount: %d\nfile: . %%d\nEND\n' % len(streamlines)
    offset = len(head % 0) + 8
    text = (head % offset).encode()
    open(path, 'wb').write(text + b'\0' * (offset - len(text)) + body)


def grid_world(aff, shape):
    ijk = np.indices(shape).reshape(3, -1).T.astype(np.float64)
    return (ijk @ aff[:3, :3].T + aff[:3, 3]).reshape(shape + (3,))


def ball(aff, shape, center, radius):
    d = np.linalg.norm(grid_world(aff, shape) - np.asarray(center), axis=-1)
    return d <= radius


def face_points(aff, mask, rng, count):
    """Points within a few ulps of the faces between set and unset voxels
    (and of the image's outer faces next to set voxels)."""
    shape = mask.shape
    padded = np.pad(mask, 1)
    faces = []
    for axis in range(3):
        for side in (-1, 1):
            neighbour = np.roll(padded, -side, axis=axis)[1:-1, 1:-1, 1:-1]
            for ijk in np.argwhere(mask & ~neighbour):
                face = ijk.astype(np.float64)
                face[axis] += 0.5 * side
                faces.append(face)
    faces = np.array(faces)
    faces = faces[rng.choice(len(faces), min(count, len(faces)), replace=False)]
    faces = np.repeat(faces, 4, axis=0)  # each with its own perturbation
    world = faces @ aff[:3, :3].T + aff[:3, 3]
    out = []
    for p in world.astype(np.float32):
        q = p.copy()
        for k in range(3):
            for _ in range(int(rng.integers(0, 4))):
                q[k] = np.nextafter(q[k], np.float32(np.inf) if rng.integers(2) else np.float32(-np.inf))
        out.append([q, q])
    return out


def masks(out):
    rng = np.random.default_rng(41)
    # RAS, 2 mm: a ball about (25, 0, 0), on the fibres' path.
    ras = affine((0, 0, 0), (2.0, 2.0, 2.0), (-50.0, -50.0, -36.0))
    shape = (51, 51, 37)
    blob = ball(ras, shape, (25, 0, 0), 8.0)
    nib.save(nib.Nifti1Image(blob.astype(np.uint8), ras, dtype=np.uint8), os.path.join(out, 'blob.nii'))
    # Oblique, permuted and flipped (MRtrix3 realigns it), anisotropic: a
    # ball about (0, 25, 0).
    obl = affine((15, -10, 20), (1.7, 2.1, 2.5), (40.0, -45.0, -40.0), columns=(1, 0, 2), flips=(1, -1, 1))
    oshape = (48, 44, 34)
    centre = np.linalg.solve(obl[:3, :3], -obl[:3, 3])
    obl[:3, 3] -= obl[:3, :3] @ (np.array(oshape) / 2 - centre)
    oblique = ball(obl, oshape, (0, 25, 0), 7.0)
    nib.save(nib.Nifti1Image(oblique.astype(np.uint8), obl, dtype=np.uint8), os.path.join(out, 'oblique.nii'))
    # Non-binary float32: a bump of height 1 about (0, -25, 0) and one of
    # height -1 about (-25, 0, 0); MRtrix3 keeps |value| >= 0.5.
    w = grid_world(ras, shape)
    bumps = (np.exp(-np.sum((w - [0, -25, 0]) ** 2, -1) / (2 * 6.0 ** 2)) -
             np.exp(-np.sum((w - [-25, 0, 0]) ** 2, -1) / (2 * 5.0 ** 2))).astype(np.float32)
    nib.save(nib.Nifti1Image(bumps, ras, dtype=np.float32), os.path.join(out, 'float.nii'))
    # gzip, LAS storage (x flipped), int16 scaled by 0.01: set where the
    # scaled value reaches 0.5, a ball about (0, 25, 0) and (25, 0, 0).
    las = affine((0, 0, 0), (2.5, 2.5, 2.5), (50.0, -50.0, -37.5), flips=(-1, 1, 1))
    lshape = (41, 41, 31)
    level = np.maximum(100 * (1 - np.linalg.norm(grid_world(las, lshape) - [0, 25, 0], axis=-1) / 14),
                       100 * (1 - np.linalg.norm(grid_world(las, lshape) - [25, 0, 0], axis=-1) / 10))
    stored = np.clip(np.round(level), -10, 100).astype(np.int16)
    img = nib.Nifti1Image(stored, las, dtype=np.int16)
    img.header.set_slope_inter(0.01, 0.0)
    nib.save(img, os.path.join(out, 'blob_gz.nii.gz'))
    raw = gzip.open(os.path.join(out, 'blob_gz.nii.gz')).read()
    assert np.isclose(np.frombuffer(raw[112:116], '<f4')[0], 0.01)

    for name, path in [('blob', 'blob.nii'), ('oblique', 'oblique.nii'), ('float', 'float.nii'),
                       ('blob_gz', 'blob_gz.nii.gz')]:
        img = nib.load(os.path.join(out, path))
        set_voxels = mrtrix_mask(img.get_fdata()).astype(bool)
        write_tck(os.path.join(out, 'faces_' + name + '.tck'), face_points(img.affine, set_voxels, rng, 1000))


if __name__ == '__main__':
    if len(sys.argv) != 3 or sys.argv[1] not in ('volumes', 'masks'):
        sys.exit(__doc__)
    os.makedirs(sys.argv[2], exist_ok=True)
    (volumes if sys.argv[1] == 'volumes' else masks)(sys.argv[2])
