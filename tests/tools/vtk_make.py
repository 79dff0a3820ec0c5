#!/usr/bin/python3
"""Legacy VTK PolyData test files written from the file-format spec.

  vtk_make.py OUTDIR

writes OUTDIR/<case>.vtk and OUTDIR/<case>.json for each case. The JSON holds
what a reader must produce: streamlines (points gathered by index, float32,
flattened), per-point and per-streamline arrays ({name: {components,
values}}) and substrings expected in its warnings. Binary files are
big-endian, as the spec says; lines share and reorder points so that
gathering by index is exercised.
"""
import json
import sys

import numpy as np


def be(values, dtype):
    return np.asarray(values).astype(np.dtype(dtype).newbyteorder('>')).tobytes()


def ascii_values(values, per_line=9):
    flat = [repr(float(v)) if isinstance(v, (float, np.floating)) else str(int(v)) for v in np.ravel(values)]
    return '\n'.join(' '.join(flat[i:i + per_line]) for i in range(0, len(flat), per_line)) + '\n'


class Case:
    def __init__(self, seed, n_points=40, n_lines=7, point_dtype='f4'):
        rng = np.random.default_rng(seed)
        self.points = rng.uniform(-80, 80, (n_points, 3)).astype(point_dtype)
        self.lines = []
        for i in range(n_lines):
            k = 1 if i == 2 else int(rng.integers(2, 12))
            self.lines.append(rng.integers(0, n_points, k).astype(np.int64))
        self.fa = rng.uniform(0, 1, n_points).astype('f4')
        self.rgb = rng.integers(0, 256, (n_points, 3)).astype(np.uint8)
        self.tangent = rng.normal(0, 1, (n_points, 3)).astype('f8')
        self.length = np.array([len(line) for line in self.lines], dtype=np.int32)
        self.weight = rng.uniform(0, 3, n_lines).astype('f8')

    def expected(self, point_arrays, line_arrays, warnings=()):
        ids = np.concatenate(self.lines)
        return {
            'streamlines': [self.points[line].astype('f4').astype('f8').ravel().tolist() for line in self.lines],
            'per_point': {name: {'components': int(np.asarray(v).reshape(len(self.points), -1).shape[1]),
                                 'values': np.asarray(v).reshape(len(self.points), -1)[ids].astype('f4')
                                 .astype('f8').ravel().tolist()}
                          for name, v in point_arrays.items()},
            'per_streamline': {name: {'components': int(np.asarray(v).reshape(len(self.lines), -1).shape[1]),
                                      'values': np.asarray(v).astype('f4').astype('f8').ravel().tolist()}
                               for name, v in line_arrays.items()},
            'warnings': list(warnings),
        }


def binary_classic(outdir):
    """VTK < 5.1 layout: LINES n size with interleaved int32 records; SCALARS
    with and without a component count; CELL_DATA SCALARS and FIELD."""
    c = Case(1)
    words = []
    for line in c.lines:
        words += [len(line)] + line.tolist()
    out = b'# vtk DataFile Version 3.0\nclassic binary streamlines\nBINARY\nDATASET POLYDATA\n'
    out += b'POINTS %d float\n' % len(c.points) + be(c.points, 'f4') + b'\n'
    out += b'LINES %d %d\n' % (len(c.lines), len(words)) + be(words, 'i4') + b'\n'
    out += b'POINT_DATA %d\n' % len(c.points)
    out += b'SCALARS fa float\nLOOKUP_TABLE default\n' + be(c.fa, 'f4') + b'\n'
    out += b'COLOR_SCALARS rgb 3\n' + c.rgb.tobytes() + b'\n'
    out += b'NORMALS tangent double\n' + be(c.tangent, 'f8') + b'\n'
    out += b'CELL_DATA %d\n' % len(c.lines)
    out += b'SCALARS length int 1\nLOOKUP_TABLE default\n' + be(c.length, 'i4') + b'\n'
    out += b'FIELD FieldData 1\nweight 1 %d double\n' % len(c.lines) + be(c.weight, 'f8') + b'\n'
    open(f'{outdir}/binary_classic.vtk', 'wb').write(out)
    return c.expected({'fa': c.fa, 'rgb': c.rgb / np.float32(255), 'tangent': c.tangent},
                      {'length': c.length, 'weight': c.weight})


def binary_51(outdir):
    """VTK 5.1 layout: OFFSETS / CONNECTIVITY vtktypeint64, double points,
    METADATA after an array, a lookup table, a string FIELD array to skip."""
    c = Case(2, point_dtype='f8')
    offsets = np.cumsum([0] + [len(line) for line in c.lines])
    out = b'# vtk DataFile Version 5.1\nvtk 5.1 streamlines\nBINARY\nDATASET POLYDATA\n'
    out += b'FIELD FieldData 1\nTIME 1 1 double\n' + be([3.5], 'f8') + b'\n'
    out += b'POINTS %d double\n' % len(c.points) + be(c.points, 'f8') + b'\n'
    out += b'LINES %d %d\n' % (len(offsets), offsets[-1])
    out += b'OFFSETS vtktypeint64\n' + be(offsets, 'i8') + b'\n'
    out += b'CONNECTIVITY vtktypeint64\n' + be(np.concatenate(c.lines), 'i8') + b'\n'
    out += b'POINT_DATA %d\n' % len(c.points)
    out += b'SCALARS fa float 1\nLOOKUP_TABLE my_table\n' + be(c.fa, 'f4') + b'\n'
    out += b'LOOKUP_TABLE my_table 2\n' + bytes([0, 0, 0, 255, 255, 255, 255, 255]) + b'\n'
    out += b'VECTORS tangent double\n' + be(c.tangent, 'f8') + b'\n'
    out += b'METADATA\nCOMPONENT_NAMES\nx\ny\nz\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\n'
    out += b'DATA 2 0 1.5\n\n'
    out += b'CELL_DATA %d\n' % len(c.lines)
    names = [b'cst', b'af', b'unnamed bundle'] + [b'x'] * (len(c.lines) - 3)
    out += b'FIELD FieldData 2\nbundle 1 %d string\n' % len(c.lines)
    for n in names:
        out += bytes([0xC0 | len(n)]) + n
    out += b'\nweight 1 %d double\n' % len(c.lines) + be(c.weight, 'f8') + b'\n'
    open(f'{outdir}/binary_51.vtk', 'wb').write(out)
    return c.expected({'fa': c.fa, 'tangent': c.tangent}, {'weight': c.weight},
                      ["dataset field data", "FIELD array 'bundle' skipped"])


def ascii_51(outdir):
    """ASCII with the 5.1 layout (int32 offsets), lower-case keywords."""
    c = Case(3)
    offsets = np.cumsum([0] + [len(line) for line in c.lines])
    out = '# vtk DataFile Version 5.1\nascii 5.1\nASCII\nDATASET POLYDATA\n'
    out += f'POINTS {len(c.points)} float\n' + ascii_values(c.points)
    out += f'lines {len(offsets)} {offsets[-1]}\n'
    out += 'OFFSETS vtktypeint32\n' + ascii_values(offsets)
    out += 'CONNECTIVITY vtktypeint32\n' + ascii_values(np.concatenate(c.lines))
    out += f'point_data {len(c.points)}\n'
    out += 'SCALARS fa%20value float\nLOOKUP_TABLE default\n' + ascii_values(c.fa)
    out += f'CELL_DATA {len(c.lines)}\nSCALARS length int\n' + ascii_values(c.length)
    open(f'{outdir}/ascii_51.vtk', 'w').write(out)
    return c.expected({'fa value': c.fa}, {'length': c.length})


def binary_with_vertices(outdir):
    """VERTICES before LINES: the lines' CELL_DATA rows follow the vertices'
    (vtkPolyData numbers cells verts, lines, polys, strips)."""
    c = Case(4)
    words = []
    for line in c.lines:
        words += [len(line)] + line.tolist()
    out = b'# vtk DataFile Version 4.2\nwith vertices\nBINARY\nDATASET POLYDATA\n'
    out += b'POINTS %d float\n' % len(c.points) + be(c.points, 'f4') + b'\n'
    out += b'VERTICES 2 4\n' + be([1, 0, 1, 5], 'i4') + b'\n'
    out += b'LINES %d %d\n' % (len(c.lines), len(words)) + be(words, 'i4') + b'\n'
    out += b'CELL_DATA %d\n' % (len(c.lines) + 2)
    out += b'SCALARS id int\nLOOKUP_TABLE default\n' + be(np.arange(len(c.lines) + 2), 'i4') + b'\n'
    out += b'POINT_DATA %d\n' % len(c.points)
    out += b'SCALARS fa float\nLOOKUP_TABLE default\n' + be(c.fa, 'f4') + b'\n'
    open(f'{outdir}/binary_with_vertices.vtk', 'wb').write(out)
    return c.expected({'fa': c.fa}, {'id': np.arange(2, len(c.lines) + 2)}, ['vertices cells'])


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    for make in (binary_classic, binary_51, ascii_51, binary_with_vertices):
        expected = make(outdir)
        with open(f'{outdir}/{make.__name__}.json', 'w') as f:
            json.dump(expected, f)
