#!/usr/bin/python3
"""Independent TRX reference for fibscope's tests, written from the TRX
specification (https://github.com/tee-ar-ex/trx-spec) with numpy, zipfile
and json only.

  make OUT [options]       writes a TRX (zip or directory) from seeded random
                           data and prints its contents as JSON (see `read`)
  read PATH                reads a TRX (zip or directory) and prints JSON:
                           counts, dtypes, every value, member compression
  zip DIR OUT              zips a TRX directory (--method, --top-folder)
  batch                    runs one command line per stdin line in this
                           process (saves interpreter start-up), output per line
  half-to-float OUT        all 65536 float16 bit patterns as float32 (LE)
  float-to-half IN OUT     float32 (LE) file -> float16 bits (LE), numpy rounding

Values are printed as JSON numbers: float64 repr is exact, so a float16 or
float32 value compares exactly after conversion to float.
"""
import argparse
import json
import os
import sys
import zipfile

import numpy as np

DTYPES = {"int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64",
          "float16", "float32", "float64", "bit"}


def np_dtype(name):
    return np.dtype("bool") if name == "bit" else np.dtype(name).newbyteorder("<")


def split_member(file_name):
    """'fa.3.float32' -> ('fa', 3, 'float32'); NCOMP omitted means 1."""
    base, dtype = file_name.rsplit(".", 1)
    if dtype not in DTYPES:
        raise ValueError("unknown dtype in " + file_name)
    head, _, last = base.rpartition(".")
    if head and last.isdigit():
        return head, int(last), dtype
    return base, 1, dtype


# ---------------------------------------------------------------------------
# make

def generate(args):
    """Returns {member name: bytes} and the header dict."""
    rng = np.random.default_rng(args.seed)
    n = args.streamlines
    lengths = rng.integers(1, 30, size=n)
    if args.empty and n > 2:
        lengths[n // 2] = 0
    nv = int(lengths.sum())
    offsets = np.zeros(n + 1, dtype=np.int64)
    offsets[1:] = np.cumsum(lengths)
    positions = rng.uniform(-80.0, 80.0, size=(nv, 3))
    header = {
        "VOXEL_TO_RASMM": [[1.25, 0.0, 0.0, -90.0], [0.0, 1.25, 0.0, -126.0], [0.0, 0.0, 1.25, -72.0],
                           [0.0, 0.0, 0.0, 1.0]],
        "DIMENSIONS": [145, 174, 145],
        "NB_VERTICES": nv,
        "NB_STREAMLINES": n,
        "SOURCE": "trx_reference.py",
    }
    members = {}
    members["positions.3." + args.positions] = positions.astype(np_dtype(args.positions)).tobytes()
    stored_offsets = offsets if args.sentinel else offsets[:-1]
    members["offsets." + args.offsets] = stored_offsets.astype(np_dtype(args.offsets)).tobytes()
    if args.data:
        members["dps/weight.float32"] = rng.uniform(0, 2, size=n).astype("<f4").tobytes()
        members["dps/colour.3.uint8"] = rng.integers(0, 256, size=(n, 3)).astype("u1").tobytes()
        members["dps/cluster.int64"] = rng.integers(-5, 5, size=n).astype("<i8").tobytes()
        members["dpv/fa.float16"] = rng.uniform(0, 1, size=nv).astype("<f2").tobytes()
        members["dpv/dir.3.float64"] = rng.uniform(-1, 1, size=(nv, 3)).astype("<f8").tobytes()
        members["dpv/label.int16"] = rng.integers(-300, 300, size=nv).astype("<i2").tobytes()
    if args.groups and n > 0:
        members["groups/left.uint32"] = np.sort(rng.choice(n, size=max(1, n // 3), replace=False)).astype("<u4").tobytes()
        members["groups/right.uint16"] = np.arange(0, n, 2).astype("<u2").tobytes()
        members["dpg/left/mean_fa.float32"] = np.array([0.42], dtype="<f4").tobytes()
        members["dpg/left/colour.3.uint8"] = np.array([255, 128, 0], dtype="u1").tobytes()
    members["header.json"] = json.dumps(header, indent=1).encode()
    return members


def write_members(members, out, layout, top_folder):
    prefix = top_folder + "/" if top_folder else ""
    if layout == "dir":
        for name, data in members.items():
            path = os.path.join(out, prefix + name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "wb") as f:
                f.write(data)
        return
    with zipfile.ZipFile(out, "w") as zf:
        if top_folder:
            zf.writestr(zipfile.ZipInfo(prefix), b"")  # folder entry, as `zip -r` makes
        for i, (name, data) in enumerate(sorted(members.items())):
            if layout == "stored":
                method = zipfile.ZIP_STORED
            elif layout == "deflated":
                method = zipfile.ZIP_DEFLATED
            else:  # mixed
                method = zipfile.ZIP_DEFLATED if i % 2 else zipfile.ZIP_STORED
            zf.writestr(zipfile.ZipInfo(prefix + name, date_time=(2024, 1, 1, 0, 0, 0)), data, compress_type=method)


def cmd_make(args):
    members = generate(args)
    write_members(members, args.out, args.layout, args.top_folder)
    print(json.dumps(describe(args.out)))


# ---------------------------------------------------------------------------
# read

class Source:
    """Members of a TRX zip or directory, names relative to the TRX root."""

    def __init__(self, path):
        self.path = path
        self.compression = {}
        if os.path.isdir(path):
            self.zip = None
            self.names = []
            for root, _, files in os.walk(path):
                for f in files:
                    self.names.append(os.path.relpath(os.path.join(root, f), path).replace(os.sep, "/"))
            self.prefix = ""
        else:
            self.zip = zipfile.ZipFile(path)
            infos = [i for i in self.zip.infolist() if not i.is_dir()]
            all_names = [i.filename for i in infos]
            self.prefix = ""
            if "header.json" not in all_names:
                tops = [n[:-len("header.json")] for n in all_names
                        if n.endswith("/header.json") and n.count("/") == 1]
                if len(tops) == 1:
                    self.prefix = tops[0]
            self.names = []
            for info in infos:
                if info.filename.startswith(self.prefix):
                    name = info.filename[len(self.prefix):]
                    self.names.append(name)
                    self.compression[name] = "stored" if info.compress_type == zipfile.ZIP_STORED else "deflated"

    def read(self, name):
        if self.zip is not None:
            return self.zip.read(self.prefix + name)
        with open(os.path.join(self.path, name), "rb") as f:
            return f.read()


def values_of(data, dtype, components):
    arr = np.frombuffer(data, dtype=np_dtype(dtype))
    return {"dtype": dtype, "components": components, "values": [float(v) for v in arr.astype(np.float64)]}


def describe(path):
    src = Source(path)
    header = json.loads(src.read("header.json"))
    out = {"header": header, "nb_streamlines": header["NB_STREAMLINES"], "nb_vertices": header["NB_VERTICES"],
           "members": sorted(src.names), "compression": src.compression,
           "dps": {}, "dpv": {}, "groups": {}, "dpg": {}}
    for name in src.names:
        parts = name.split("/")
        if name == "header.json" or name.endswith(".json"):
            continue
        base, comps, dtype = split_member(parts[-1])
        data = src.read(name)
        if len(parts) == 1 and base == "positions":
            pos = np.frombuffer(data, dtype=np_dtype(dtype)).astype(np.float64)
            out["positions_dtype"] = dtype
            out["positions"] = [float(v) for v in pos]
            out["positions_sum"] = float(pos.sum())
        elif len(parts) == 1 and base == "offsets":
            offs = np.frombuffer(data, dtype=np_dtype(dtype)).astype(np.int64)
            out["offsets_dtype"] = dtype
            out["offsets_count"] = int(offs.size)
            if offs.size == header["NB_STREAMLINES"]:  # files without the final sentinel
                offs = np.append(offs, header["NB_VERTICES"])
            out["lengths"] = [int(v) for v in np.diff(offs)]
        elif parts[0] in ("dps", "dpv"):
            out[parts[0]][base] = values_of(data, dtype, comps)
        elif parts[0] == "groups":
            out["groups"][base] = {"dtype": dtype,
                                   "indices": [int(v) for v in np.frombuffer(data, dtype=np_dtype(dtype))]}
        elif parts[0] == "dpg":
            out["dpg"].setdefault(parts[1], {})[base] = values_of(data, dtype, comps)
    return out


def cmd_read(args):
    print(json.dumps(describe(args.path)))


# ---------------------------------------------------------------------------
# zip, half

def cmd_zip(args):
    method = zipfile.ZIP_STORED if args.method == "stored" else zipfile.ZIP_DEFLATED
    prefix = args.top_folder + "/" if args.top_folder else ""
    with zipfile.ZipFile(args.out, "w") as zf:
        for root, _, files in sorted(os.walk(args.dir)):
            for f in sorted(files):
                full = os.path.join(root, f)
                rel = os.path.relpath(full, args.dir).replace(os.sep, "/")
                with open(full, "rb") as fh:
                    zf.writestr(zipfile.ZipInfo(prefix + rel, date_time=(2024, 1, 1, 0, 0, 0)), fh.read(),
                                compress_type=method)


def cmd_half_to_float(args):
    np.arange(65536, dtype=np.uint16).view(np.float16).astype("<f4").tofile(args.out)


def cmd_float_to_half(args):
    with np.errstate(over="ignore"):
        np.fromfile(args.input, dtype="<f4").astype("<f2").view("<u2").tofile(args.out)


def cmd_batch(args):
    parser = make_parser()
    for line in sys.stdin:
        if line.strip():
            sub = parser.parse_args(line.split())
            sub.func(sub)
            sys.stdout.flush()


def make_parser():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    m = sub.add_parser("make")
    m.add_argument("out")
    m.add_argument("--layout", choices=["dir", "stored", "deflated", "mixed"], default="stored")
    m.add_argument("--positions", choices=["float16", "float32", "float64"], default="float32")
    m.add_argument("--offsets", choices=["uint32", "uint64", "int32", "int64"], default="uint64")
    m.add_argument("--no-sentinel", dest="sentinel", action="store_false",
                   help="NB_STREAMLINES offsets, as files before the spec added the final NB_VERTICES")
    m.add_argument("--top-folder", default="")
    m.add_argument("--streamlines", type=int, default=20)
    m.add_argument("--seed", type=int, default=1)
    m.add_argument("--data", action="store_true", help="dps and dpv arrays")
    m.add_argument("--groups", action="store_true", help="groups and dpg")
    m.add_argument("--empty", action="store_true", help="one streamline without points")
    m.set_defaults(func=cmd_make)
    r = sub.add_parser("read")
    r.add_argument("path")
    r.set_defaults(func=cmd_read)
    z = sub.add_parser("zip")
    z.add_argument("dir")
    z.add_argument("out")
    z.add_argument("--method", choices=["stored", "deflated"], default="stored")
    z.add_argument("--top-folder", default="")
    z.set_defaults(func=cmd_zip)
    h = sub.add_parser("half-to-float")
    h.add_argument("out")
    h.set_defaults(func=cmd_half_to_float)
    f = sub.add_parser("float-to-half")
    f.add_argument("input")
    f.add_argument("out")
    f.set_defaults(func=cmd_float_to_half)
    b = sub.add_parser("batch")
    b.set_defaults(func=cmd_batch)
    return p


def main():
    args = make_parser().parse_args()
    args.func(args)


if __name__ == "__main__":
    sys.exit(main())
