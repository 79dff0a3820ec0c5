#!/usr/bin/env python3
"""Writes small valid .fbl tractograms into DIR (seeds for fuzz_fbl's openFbl pass).

Unlike fbl.py's container samples, these hold real fiblet records (codec
version 1, layout in shaders/shared/fiblet.h), a consistent
fiber_first_fiblet table, dps sections and the "source" JSON, as
`fibscope compress` writes them, so that mutations start from files the
fiblet reader accepts. Tables are kept small (capacity = sections) so the
files fit fuzz_fbl's -max_len=4096.
Usage: fbl_fiblets.py DIR
"""
import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fbl import fbl_bytes  # noqa: E402


def record_bytes(n):
    return (n + 11 + 3) & ~3


def record(n, p0, p1, codes, begins, ends, count):
    """One fiblet record: p0, p1 quantised to 16 bits, a code per point 2..count-1, flags."""
    r = bytearray(record_bytes(n))
    q = [max(0, min(65535, round(c * 65535))) for c in (*p0, *p1)]
    struct.pack_into("<6H", r, 0, *q)
    for k, code in enumerate(codes[:max(0, count - 2)]):
        r[12 + k] = code
    r[n + 10] = (1 if begins else 0) | (2 if ends else 0) | (count << 2)
    return bytes(r)


def tractogram(n, fibers, dps):
    """fibers: list of lists of fiblet point counts (an empty list is an empty fiber)."""
    records = b""
    first = [0]
    points = 0
    for f, counts in enumerate(fibers):
        for i, count in enumerate(counts):
            base = 0.2 + 0.1 * f + 0.01 * i
            codes = [(0x88 + 17 * k + f) & 0xFF for k in range(n - 2)]
            records += record(n, (base, 0.5, 0.5), (base + 0.002, 0.5, 0.5), codes, i == 0, i == len(counts) - 1, count)
            points += count
        first.append(first[-1] + len(counts))
    scale = 180.0
    delta = 0.5 / scale
    fields = {"codec_version": 1, "fibers": len(fibers), "fiblets": first[-1], "points": points, "n": n,
              "record_bytes": record_bytes(n), "translation": (-90.0, -126.0, -72.0), "scale": scale,
              "delta": delta, "delta_mm": delta * scale, "alpha": math.radians(20.0), "v": (1.0, 0.0, 0.0)}
    source = {"path": "brain.trk", "format": "trk", "file_bytes": 1000, "declared_streamlines": len(fibers),
              "declared_points": points, "properties": [["voxel_order", "LAS"]],
              "space": {"voxel_to_rasmm": [1, 0, 0, -90, 0, 1, 0, -126, 0, 0, 1, -72, 0, 0, 0, 1],
                        "dimensions": [181, 217, 181], "voxel_sizes": [1, 1, 1], "voxel_order": "LAS"},
              "per_streamline": [{"name": name, "components": k, "dtype": "float32"} for name, k in dps],
              "dropped_per_point": [{"name": "fa", "components": 1, "dtype": "float32"}]}
    lengths = [3.5 * sum(c) for c in fibers]
    sections = [("fiblets", "uint32", 1, list(struct.unpack("<%dI" % (len(records) // 4), records))),
                ("fiber_first_fiblet", "uint64", 1, first),
                ("fiber_length_mm", "float32", 1, lengths)]
    for name, k in dps:
        sections.append(("dps/" + name, "float32", k, [float(i) for i in range(k * len(fibers))]))
    sections.append(("source", "utf8", 1, json.dumps(source).encode()))
    return fbl_bytes(fields, sections, capacity=len(sections))


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    seeds = {
        "fiblets_n8.fbl": tractogram(8, [[8, 3], [], [1], [8, 8, 2]], [("weight", 1)]),
        "fiblets_n12.fbl": tractogram(12, [[12, 12, 5], [2]], [("colour", 3), ("weight", 1)]),
        "fiblets_n60.fbl": tractogram(60, [[60, 17]], []),
        "fiblets_none.fbl": tractogram(8, [], []),
    }
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
