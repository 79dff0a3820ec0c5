#!/usr/bin/python3
"""Writes small .vtp seed files for fuzz/fuzz_vtp.cpp into the directory argv[1].

Written by VTK itself (Debian's python3-vtk9, installed by `./setup.sh test`):
five points, two lines, a point and a cell array, in each data mode (ascii,
inline binary, appended raw and base64), with no, zlib, LZ4 and LZMA
compression and both header widths. Without VTK, one hand-written ASCII file.
"""
import os
import sys

out = sys.argv[1]
sys.path.pop(0)  # this folder's vtk.py (the legacy seeds) is not VTK
try:
    import vtk
except ImportError:
    with open(os.path.join(out, 'ascii.vtp'), 'w') as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">'
                '<PolyData><Piece NumberOfPoints="3" NumberOfLines="1"><Points>'
                '<DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 2 1 0</DataArray>'
                '</Points><Lines><DataArray type="Int64" Name="connectivity" format="ascii">0 1 2</DataArray>'
                '<DataArray type="Int64" Name="offsets" format="ascii">3</DataArray></Lines></Piece>'
                '</PolyData></VTKFile>\n')
    sys.exit(0)

pd = vtk.vtkPolyData()
points = vtk.vtkPoints()
for p in [(0, 0, 0), (1, 0, 0), (2, 1, 0), (3, 1, 1), (4, 2, 1)]:
    points.InsertNextPoint(*p)
pd.SetPoints(points)
lines = vtk.vtkCellArray()
for ids in ([0, 1, 2], [4, 3]):
    lines.InsertNextCell(len(ids))
    for i in ids:
        lines.InsertCellPoint(i)
pd.SetLines(lines)
fa = vtk.vtkFloatArray()
fa.SetName('fa')
for v in (0.1, 0.2, 0.3, 0.4, 0.5):
    fa.InsertNextValue(v)
pd.GetPointData().AddArray(fa)
bundle = vtk.vtkIntArray()
bundle.SetName('bundle')
bundle.InsertNextValue(3)
bundle.InsertNextValue(4)
pd.GetCellData().AddArray(bundle)

for name, mode, compressor, header64, encode in [
        ('ascii', 'Ascii', None, False, True), ('binary_zlib', 'Binary', 'ZLib', False, True),
        ('appended_raw', 'Appended', None, False, False), ('appended_b64_lz4', 'Appended', 'LZ4', False, True),
        ('appended_raw_lzma_u64', 'Appended', 'LZMA', True, False)]:
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(os.path.join(out, name + '.vtp'))
    w.SetInputData(pd)
    getattr(w, 'SetDataModeTo' + mode)()
    getattr(w, 'SetCompressorTypeTo' + (compressor or 'None'))()
    w.SetHeaderTypeToUInt64() if header64 else w.SetHeaderTypeToUInt32()
    w.SetEncodeAppendedData(1 if encode else 0)
    w.Write()
