#!/usr/bin/env python3
"""Writes small valid .fbl files into DIR (seeds for fuzz_fbl).

Written from docs/FBL_FORMAT.md alone, with its own CRC-32C, so it is also an
independent writer that the C++ reader must accept (tests/unit/fbl_file_test.cpp).
Usage: fbl.py DIR
"""
import json
import os
import struct
import sys


def crc32c(data, crc=0):
    crc ^= 0xFFFFFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


DTYPES = {"uint8": (1, "B"), "uint16": (2, "H"), "uint32": (3, "I"), "uint64": (4, "Q"),
          "int8": (5, "b"), "int16": (6, "h"), "int32": (7, "i"), "int64": (8, "q"),
          "float32": (9, "f"), "float64": (10, "d"), "utf8": (11, "B")}


def align(n):
    return (n + 63) // 64 * 64


def fbl_bytes(fields, sections, capacity):
    """sections: list of (name, dtype, components, values or bytes)."""
    table_end = 256 + 96 * capacity
    body = bytearray(align(table_end))
    table = bytearray()
    for name, dtype, components, values in sections:
        code, fmt = DTYPES[dtype]
        data = values if isinstance(values, bytes) else struct.pack("<%d%s" % (len(values), fmt), *values)
        count = len(data) // (struct.calcsize(fmt) * components)
        offset = len(body)
        body += data
        body += bytes(align(len(body)) - len(body))
        table += name.encode().ljust(48, b"\0")
        table += struct.pack("<IIQQQI12x", code, components, count, offset, len(data), crc32c(data))
    body[256:256 + len(table)] = table
    header = bytearray(256)
    header[0:8] = b"FIBLETS\0"
    struct.pack_into("<IIII", header, 8, 1, 256, 0, fields["codec_version"])
    struct.pack_into("<QQQII", header, 24, fields["fibers"], fields["fiblets"], fields["points"],
                     fields["n"], fields["record_bytes"])
    struct.pack_into("<8d", header, 56, *fields["translation"], fields["scale"], fields["delta"],
                     fields["delta_mm"], fields["alpha"], 0.0)  # the last double is overwritten by V below
    struct.pack_into("<3fI", header, 112, *fields["v"], len(sections))
    struct.pack_into("<QIIQ", header, 128, 256, capacity, crc32c(bytes(table)), len(body))
    struct.pack_into("<I", header, 252, crc32c(bytes(header[:252])))
    body[0:256] = header
    return bytes(body)


def sample():
    fields = {"codec_version": 1, "fibers": 2, "fiblets": 3, "points": 70, "n": 60, "record_bytes": 16,
              "translation": (-90.0, -126.0, -72.0), "scale": 180.0, "delta": 0.5 / 180.0, "delta_mm": 0.5,
              "alpha": 0.5, "v": (0.25, 0.5, 0.75)}
    sections = [("fiblets", "uint32", 1, list(range(12))),
                ("fiber_first_fiblet", "uint64", 1, [0, 2, 3]),
                ("fiber_length_mm", "float32", 1, [30.5, 4.0]),
                ("dps/colour", "float32", 3, [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
                ("source", "utf8", 1, json.dumps({"input": "brain.trk", "format": "trk"}).encode())]
    return fields, sections


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    fields, sections = sample()
    with open(os.path.join(out, "sample.fbl"), "wb") as f:
        f.write(fbl_bytes(fields, sections, capacity=5))
    empty = dict(fields, fibers=0, fiblets=0, points=0)
    with open(os.path.join(out, "empty.fbl"), "wb") as f:
        f.write(fbl_bytes(empty, [("fiblets", "uint32", 1, []), ("fiber_first_fiblet", "uint64", 1, [0])], 2))
    with open(os.path.join(out, "no_sections.fbl"), "wb") as f:
        f.write(fbl_bytes(empty, [], 0))


if __name__ == "__main__":
    main()
