#!/usr/bin/python3
"""Writes small legacy .vtk seed files for fuzz/fuzz_vtk.cpp into the directory argv[1].

From the legacy VTK file-format spec: ASCII and big-endian BINARY, the
classic LINES layout and the 5.1 OFFSETS/CONNECTIVITY layout, point and cell
attributes (SCALARS with a lookup table, COLOR_SCALARS, VECTORS, FIELD with a
string array), VERTICES and METADATA.
"""
import struct
import sys

HEAD = '# vtk DataFile Version {}\nseed\n{}\nDATASET POLYDATA\n'
POINTS = [(0, 0, 0), (1, 0, 0), (2, 1, 0), (3, 1, 1), (4, 2, 1)]
LINES = [[0, 1, 2], [4, 3], [2]]


def be(fmt, values):
    return struct.pack('>%d%s' % (len(values), fmt), *values)


def flat(points):
    return [c for p in points for c in p]


def ascii_classic():
    words = [w for line in LINES for w in [len(line)] + line]
    s = HEAD.format('3.0', 'ASCII')
    s += 'POINTS %d float\n%s\n' % (len(POINTS), ' '.join(map(str, flat(POINTS))))
    s += 'LINES %d %d\n%s\n' % (len(LINES), len(words), ' '.join(map(str, words)))
    s += 'POINT_DATA %d\nSCALARS fa float 1\nLOOKUP_TABLE default\n0.1 0.2 0.3 0.4 0.5\n' % len(POINTS)
    s += 'VECTORS dir float\n' + ' '.join(['1 0 0'] * len(POINTS)) + '\n'
    s += 'CELL_DATA 3\nSCALARS bundle int\nLOOKUP_TABLE default\n1 2 3\n'
    s += 'FIELD FieldData 1\nname 1 3 string\ncst\naf\nx%20y\n'
    return s.encode()


def ascii_51():
    offsets = [0]
    for line in LINES:
        offsets.append(offsets[-1] + len(line))
    s = HEAD.format('5.1', 'ASCII')
    s += 'POINTS %d double\n%s\n' % (len(POINTS), ' '.join(map(str, flat(POINTS))))
    s += 'LINES %d %d\nOFFSETS vtktypeint64\n%s\nCONNECTIVITY vtktypeint64\n%s\n' % (
        len(offsets), offsets[-1], ' '.join(map(str, offsets)), ' '.join(str(i) for line in LINES for i in line))
    s += 'POINT_DATA %d\nSCALARS fa float\nLOOKUP_TABLE default\n0 1 2 3 4\n' % len(POINTS)
    s += 'METADATA\nINFORMATION 0\n\n'
    return s.encode()


def binary_classic():
    words = [w for line in LINES for w in [len(line)] + line]
    s = HEAD.format('4.2', 'BINARY').encode()
    s += b'POINTS %d float\n' % len(POINTS) + be('f', flat(POINTS)) + b'\n'
    s += b'VERTICES 1 2\n' + be('i', [1, 0]) + b'\n'
    s += b'LINES %d %d\n' % (len(LINES), len(words)) + be('i', words) + b'\n'
    s += b'POINT_DATA %d\nCOLOR_SCALARS rgb 3\n' % len(POINTS) + bytes(range(3 * len(POINTS))) + b'\n'
    s += b'LOOKUP_TABLE t 1\n' + bytes([1, 2, 3, 4]) + b'\n'
    return s


def binary_51():
    offsets = [0]
    for line in LINES:
        offsets.append(offsets[-1] + len(line))
    s = HEAD.format('5.1', 'BINARY').encode()
    s += b'POINTS %d double\n' % len(POINTS) + be('d', flat(POINTS)) + b'\n'
    s += b'LINES %d %d\nOFFSETS vtktypeint64\n' % (len(offsets), offsets[-1]) + be('q', offsets) + b'\n'
    s += b'CONNECTIVITY vtktypeint64\n' + be('q', [i for line in LINES for i in line]) + b'\n'
    s += b'CELL_DATA 3\nFIELD FieldData 2\nw 1 3 double\n' + be('d', [0.5, 1.5, 2.5]) + b'\n'
    s += b'label 1 3 string\n' + b''.join(bytes([0xC0 | len(t)]) + t for t in (b'a', b'bc', b'')) + b'\n'
    return s


def main():
    out = sys.argv[1]
    for name, make in (('ascii_classic.vtk', ascii_classic), ('ascii_51.vtk', ascii_51),
                       ('binary_classic.vtk', binary_classic), ('binary_51.vtk', binary_51)):
        with open(f'{out}/{name}', 'wb') as f:
            f.write(make())


if __name__ == '__main__':
    main()
