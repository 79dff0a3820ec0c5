#!/usr/bin/python3
"""Seeds for fuzz_tt: small MAT-4 files as inside a DSI Studio .tt.gz.

  fuzz/seeds/tt.py DIR

Little- and big-endian files with dimension, voxel_size, trans_to_mni
(1 x 16 and 4 x 4), a report text and one or two track blocks of a few
tracts (steps across the int8 range), built with struct from the MAT-4
layout (no scipy needed).
"""
import struct
import sys


def matrix(name, precision, rows, cols, data, big=False, text=False):
    order = '>' if big else '<'
    mopt = (1000 if big else 0) + 10 * precision + (1 if text else 0)
    return struct.pack(order + '5i', mopt, rows, cols, 0, len(name) + 1) + name.encode() + b'\0' + data


def floats(name, values, rows, cols, big=False):
    return matrix(name, 1, rows, cols, struct.pack(('>' if big else '<') + '%df' % len(values), *values), big)


def tract(points):
    out = struct.pack('<I3i', 3 * len(points), *points[0])
    for a, b in zip(points, points[1:]):
        out += struct.pack('3b', *[b[k] - a[k] for k in range(3)])
    return out


def main():
    out = sys.argv[1]
    affine = [-2, 0, 0, 90, 0, 2, 0, -126, 0, 0, 2, -72, 0, 0, 0, 1]
    tracts = tract([(1440, 1728, 1440), (1500, 1700, 1400), (1372, 1827, 1400)]) + tract([(0, 0, 0)])
    more = tract([(100, 200, 300), (101, 199, 301), (228, 72, 173), (229, 73, 174)])
    for big in (False, True):
        body = floats('dimension', [90, 108, 90], 1, 3, big) + floats('voxel_size', [2, 2, 2], 1, 3, big)
        body += matrix('report', 0, 1, 5, struct.pack(('>' if big else '<') + '5d', *b'DSI S'), big, text=True)
        body += floats('trans_to_mni', affine, 1, 16, big)
        body += matrix('track', 5, len(tracts), 1, tracts, big) + matrix('track1', 5, len(more), 1, more, big)
        with open('%s/%s.tt' % (out, 'be' if big else 'le'), 'wb') as f:
            f.write(body)
    square = [affine[4 * c + r] for r in range(4) for c in range(4)]  # column order, as MATLAB stores 4 x 4
    with open('%s/square.tt' % out, 'wb') as f:
        f.write(floats('trans_to_mni', square, 4, 4) + matrix('track', 5, len(more), 1, more))


if __name__ == '__main__':
    main()
