#!/usr/bin/python3
"""Writes small .tck/.tsf seed files for fuzz/fuzz_tck.cpp into the directory argv[1].

Laid out from the format description (MRtrix3 docs): text header, END,
float samples, a NaN triplet after each streamline, an Inf triplet at the
end. Covers every datatype, zero-length streamlines, MRtrix-style padding,
repeated keys, a truncated file and a .tsf that matches fuzz_tck's built-in
reference tractogram (streamlines of 2, 0 and 3 points).
"""
import os
import struct
import sys

NAN = float('nan')
INF = float('inf')
FMT = {'Float32LE': '<f', 'Float32BE': '>f', 'Float64LE': '<d', 'Float64BE': '>d'}


def track_file(magic, streamlines, per_point, datatype='Float32LE', extra='', padding=0,
               count=True, terminator=True):
    head = magic + '\n' + extra + 'datatype: ' + datatype + '\n'
    if count:
        head += 'count: %d\n' % len(streamlines)
    digits = 1
    while True:
        offset = len(head) + len('file: . ') + digits + len('\nEND\n') + padding
        if len(str(offset)) == digits:
            break
        digits += 1
    out = (head + 'file: . %d\nEND\n' % offset).encode() + b'\0' * padding
    f = FMT[datatype]
    for s in streamlines:
        out += b''.join(struct.pack(f, v) for v in s)
        out += struct.pack(f, NAN) * per_point
    if terminator:
        out += struct.pack(f, INF) * per_point
    return out


def main():
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    lines = [[1, 2, 3, 4, 5, 6], [], [7, 8, 9, 10.5, -11, 12, 13, 14, 15]]
    seeds = {
        'f32le.tck': track_file('mrtrix tracks', lines, 3),
        'f32be.tck': track_file('mrtrix tracks', lines, 3, 'Float32BE'),
        'f64le.tck': track_file('mrtrix tracks', lines, 3, 'Float64LE', count=False),
        'f64be.tck': track_file('mrtrix tracks', lines, 3, 'Float64BE', extra='roi: seed a.nii\nroi: mask b.nii\n'),
        'mrtrix.tck': track_file('mrtrix tracks    ', lines, 3, padding=24,
                                 extra='command_history: tckgen x y\ntimestamp: 1.5\n'),
        'truncated.tck': track_file('mrtrix tracks', lines, 3, terminator=False)[:-5],
        'scalars.tsf': track_file('mrtrix track scalars', [[0.5, 0.25], [], [1, 2, 3]], 1),
        'scalars64.tsf': track_file('mrtrix track scalars', [[0.5, 0.25], [], [1, 2, 3]], 1, 'Float64BE'),
    }
    for name, data in seeds.items():
        with open(os.path.join(outdir, name), 'wb') as f:
            f.write(data)


if __name__ == '__main__':
    main()
