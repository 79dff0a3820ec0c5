#!/usr/bin/python3
"""Writes small .trk seed files for fuzz/fuzz_trk.cpp into the directory argv[1].

Laid out from the TrackVis spec (1000-byte header, then int32 m, m points of
x y z scalars..., properties): little- and big-endian, versions 1 and 2,
LPS voxel order with an oblique vox_to_ras, nibabel-style multi-component
names, n_count 0 (stream to EOF) and a truncated last streamline.
"""
import math
import struct
import sys


def header(order, endian='<', version=2, n_scalars=0, n_properties=0, n_count=0, scalar_names=(),
           property_names=(), vox_to_ras=None, voxel_order=b'RAS', dims=(20, 30, 40), sizes=(1.0, 1.5, 2.0)):
    h = bytearray(1000)
    h[0:6] = b'TRACK\0'
    struct.pack_into(endian + '3h', h, 6, *dims)
    struct.pack_into(endian + '3f', h, 12, *sizes)
    struct.pack_into(endian + 'h', h, 36, n_scalars)
    for i, name in enumerate(scalar_names):
        h[38 + 20 * i:38 + 20 * i + len(name)] = name
    struct.pack_into(endian + 'h', h, 238, n_properties)
    for i, name in enumerate(property_names):
        h[240 + 20 * i:240 + 20 * i + len(name)] = name
    if vox_to_ras is None:
        vox_to_ras = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    if version >= 2:
        struct.pack_into(endian + '16f', h, 440, *vox_to_ras)
    h[948:948 + len(voxel_order)] = voxel_order
    struct.pack_into(endian + 'i', h, 988, n_count)
    struct.pack_into(endian + 'i', h, 992, version)
    struct.pack_into(endian + 'i', h, 996, 1000)
    return bytes(h)


def streamlines(endian, n_scalars, n_properties, lengths):
    out = b''
    for s, m in enumerate(lengths):
        out += struct.pack(endian + 'i', m)
        for j in range(m):
            out += struct.pack(endian + '3f', 1.0 + j, 2.0 + s, 3.0 + 0.5 * j)
            out += struct.pack(endian + '%df' % n_scalars, *[0.1 * (j + k) for k in range(n_scalars)])
        out += struct.pack(endian + '%df' % n_properties, *[float(s + k) for k in range(n_properties)])
    return out


def main():
    out = sys.argv[1]
    t = math.radians(30)
    oblique = [2 * math.cos(t), -1.5 * math.sin(t), 0, -20, 2 * math.sin(t), 1.5 * math.cos(t), 0, 10, 0, 0, 2, 5,
               0, 0, 0, 1]
    lengths = [3, 1, 5]
    files = {
        'plain.trk': header(None, n_count=3) + streamlines('<', 0, 0, lengths),
        'data.trk': header(None, n_scalars=4, n_properties=2, n_count=3,
                           scalar_names=(b'fa', b'rgb\x003'), property_names=(b'pair\x002',))
        + streamlines('<', 4, 2, lengths),
        'big.trk': header(None, endian='>', n_scalars=1, n_properties=1, n_count=3, scalar_names=(b'fa',),
                          property_names=(b'w',)) + streamlines('>', 1, 1, lengths),
        'lps_oblique.trk': header(None, vox_to_ras=oblique, voxel_order=b'LPS', n_count=0)
        + streamlines('<', 0, 0, lengths),
        'v1.trk': header(None, version=1, n_scalars=2, n_count=3) + streamlines('<', 2, 0, lengths),
        'truncated.trk': (header(None, n_count=3) + streamlines('<', 0, 0, lengths))[:-5],
    }
    for name, data in files.items():
        with open(f'{out}/{name}', 'wb') as f:
            f.write(data)


if __name__ == '__main__':
    main()
