#!/usr/bin/python3
"""Streamline files written by VTK itself (Debian's python3-vtk9), the
writer 3D Slicer, dipy/FURY and ParaView use.

  vtk_real_make.py OUTDIR

writes OUTDIR/<case>.vtp or .vtk for each way VTK's writers can store a
PolyData (XML: ascii, inline binary, appended raw and base64; no, zlib, LZ4
and LZMA compression; UInt32 and UInt64 headers; both byte orders. Legacy:
ASCII and binary, file versions 4.2 and 5.1), a Slicer-style LPS file of
each kind, and OUTDIR/<case>.json with what a reader must produce, taken
from VTK's own reader of that file: the lines' points in RAS (x, y negated
where the file says LPS), the point and line arrays.
"""
import json
import os
import sys

import numpy as np
import vtk
from vtk.util import numpy_support


def build_polydata(seed=7):
    rng = np.random.default_rng(seed)
    n_points = 60
    points = rng.uniform(-70, 70, (n_points, 3)).astype(np.float32)
    pd = vtk.vtkPolyData()
    vpoints = vtk.vtkPoints()
    vpoints.SetData(numpy_support.numpy_to_vtk(points, deep=True))
    pd.SetPoints(vpoints)
    lines = vtk.vtkCellArray()
    # Lines share and reorder points (VTK refuses a one-point line).
    for i in range(9):
        k = int(rng.integers(2, 14))
        ids = rng.integers(0, n_points, k)
        lines.InsertNextCell(k)
        for p in ids:
            lines.InsertCellPoint(int(p))
    pd.SetLines(lines)
    # A vertex and a triangle: not streamlines, but they shift the lines'
    # rows in the cell data (verts come first, polys after the lines).
    verts = vtk.vtkCellArray()
    verts.InsertNextCell(1)
    verts.InsertCellPoint(3)
    pd.SetVerts(verts)
    polys = vtk.vtkCellArray()
    polys.InsertNextCell(3)
    for p in (0, 1, 2):
        polys.InsertCellPoint(p)
    pd.SetPolys(polys)
    n_cells = pd.GetNumberOfCells()

    def add(data, name, values):
        a = numpy_support.numpy_to_vtk(values, deep=True)
        a.SetName(name)
        data.AddArray(a)

    add(pd.GetPointData(), "fa", rng.uniform(0, 1, n_points).astype(np.float32))
    add(pd.GetPointData(), "rgb", rng.integers(0, 256, (n_points, 3)).astype(np.uint8))
    add(pd.GetPointData(), "tangent", rng.normal(0, 1, (n_points, 3)).astype(np.float64))
    add(pd.GetPointData(), "label", rng.integers(-30000, 30000, n_points).astype(np.int16))
    add(pd.GetCellData(), "weight", rng.uniform(0, 3, n_cells).astype(np.float64))
    add(pd.GetCellData(), "bundle", rng.integers(0, 1000, n_cells).astype(np.int32))
    return pd


def with_space(pd, space):
    out = vtk.vtkPolyData()
    out.DeepCopy(pd)
    s = vtk.vtkStringArray()
    s.SetName("SPACE")
    s.InsertNextValue(space)
    out.GetFieldData().AddArray(s)
    return out


def expected_from(path, legacy):
    if legacy:
        reader = vtk.vtkPolyDataReader()
        reader.SetFileName(path)
        reader.ReadAllFieldsOn()
        reader.ReadAllScalarsOn()
        reader.Update()
        lps = "SPACE=LPS" in (reader.GetHeader() or "")
    else:
        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(path)
        reader.Update()
    pd = reader.GetOutput()
    if not legacy:
        space = pd.GetFieldData().GetAbstractArray("SPACE")
        lps = space is not None and "LPS" in space.GetValue(0)
    points = numpy_support.vtk_to_numpy(pd.GetPoints().GetData()).astype(np.float32)
    if lps:
        points = points * np.array([-1, -1, 1], dtype=np.float32)
    n_verts = pd.GetNumberOfVerts()
    lines = pd.GetLines()
    offsets = numpy_support.vtk_to_numpy(lines.GetOffsetsArray())
    conn = numpy_support.vtk_to_numpy(lines.GetConnectivityArray())
    streamlines, point_ids = [], []
    for i in range(len(offsets) - 1):
        ids = conn[offsets[i]:offsets[i + 1]]
        point_ids.append(ids)
        streamlines.append(points[ids].ravel().tolist())

    def arrays(data, rows):
        out = {}
        for k in range(data.GetNumberOfArrays()):
            a = data.GetArray(k)
            if a is None:
                continue
            v = numpy_support.vtk_to_numpy(a).reshape(a.GetNumberOfTuples(), a.GetNumberOfComponents())
            out[a.GetName()] = {"components": a.GetNumberOfComponents(),
                                "values": v[rows].astype(np.float32).ravel().tolist()}
        return out

    all_ids = np.concatenate(point_ids) if point_ids else np.zeros(0, dtype=np.int64)
    return {"streamlines": streamlines,
            "per_point": arrays(pd.GetPointData(), all_ids),
            "per_streamline": arrays(pd.GetCellData(), np.arange(n_verts, n_verts + len(point_ids))),
            "lps": bool(lps)}


def write_xml(pd, path, mode, compressor=None, header64=False, big_endian=False, encode=True):
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(path)
    w.SetInputData(pd)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    if compressor is None:
        w.SetCompressorTypeToNone()
    else:
        {"zlib": w.SetCompressorTypeToZLib, "lz4": w.SetCompressorTypeToLZ4, "lzma": w.SetCompressorTypeToLZMA}[compressor]()
        w.SetBlockSize(1024)  # several blocks per array
    w.SetHeaderTypeToUInt64() if header64 else w.SetHeaderTypeToUInt32()
    w.SetByteOrderToBigEndian() if big_endian else w.SetByteOrderToLittleEndian()
    w.SetEncodeAppendedData(1 if encode else 0)
    assert w.Write() == 1, path


def write_legacy(pd, path, binary, version, header="vtk output"):
    w = vtk.vtkPolyDataWriter()
    w.SetFileName(path)
    w.SetInputData(pd)
    w.SetHeader(header)
    w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
    if version == 42:
        w.SetFileVersion(42)
    assert w.Write() == 1, path


def main():
    out = sys.argv[1]
    pd = build_polydata()
    cases = {}
    for mode in ("ascii", "binary", "appended"):
        for comp in ((None,) if mode == "ascii" else (None, "zlib", "lz4", "lzma")):
            for header64 in (False, True):
                encodes = (True, False) if mode == "appended" else (True,)
                for encode in encodes:
                    name = "%s_%s_%s%s" % (mode, comp or "none", "u64" if header64 else "u32",
                                            "" if encode else "_raw")
                    cases[name + ".vtp"] = lambda p, m=mode, c=comp, h=header64, e=encode: write_xml(pd, p, m, c, h, False, e)
    cases["appended_zlib_u32_raw_bigendian.vtp"] = lambda p: write_xml(pd, p, "appended", "zlib", False, True, False)
    cases["binary_none_u64_bigendian.vtp"] = lambda p: write_xml(pd, p, "binary", None, True, True)
    cases["slicer_lps_appended_zlib.vtp"] = lambda p: write_xml(with_space(pd, "LPS"), p, "appended", "zlib")
    cases["slicer_lps_ascii.vtp"] = lambda p: write_xml(with_space(pd, "LPS"), p, "ascii")
    for binary in (False, True):
        for version in (42, 51):
            cases["legacy_%s_%d.vtk" % ("binary" if binary else "ascii", version)] = \
                lambda p, b=binary, v=version: write_legacy(pd, p, b, v)
    cases["slicer_lps_legacy_binary.vtk"] = lambda p: write_legacy(pd, p, True, 51, "3D Slicer output. SPACE=LPS")
    for name, write in cases.items():
        path = os.path.join(out, name)
        write(path)
        with open(os.path.splitext(path)[0] + ".json", "w") as f:
            json.dump(expected_from(path, name.endswith(".vtk")), f)
    print("\n".join(sorted(cases)))


if __name__ == "__main__":
    main()
