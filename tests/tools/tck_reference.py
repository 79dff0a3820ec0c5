#!/usr/bin/python3
"""Independent .tck reference for fibscope's tests, built on nibabel.

  tck_reference.py write OUT.tck SEED COUNT
      writes COUNT random streamlines (deterministic for SEED) with nibabel's
      TckFile, with an extra header key, and prints them as JSON.
  tck_reference.py read IN.tck [IN2.tck ...]
      loads each file with nibabel and prints what it holds, one JSON line each.

JSON: {"count": N, "lengths": [...], "points": [x, y, z, ...],
       "header": {key: value, ...}}. Points are float32 values printed as
exact decimal doubles, so a C++ test can compare them bit for bit.
"""
import json
import sys

import numpy as np
import nibabel as nib
from nibabel.streamlines import Tractogram
from nibabel.streamlines.tck import TckFile


def as_json(streamlines, header):
    lengths = [int(len(s)) for s in streamlines]
    points = np.concatenate([np.asarray(s, dtype=np.float32).reshape(-1, 3) for s in streamlines]) \
        if streamlines else np.zeros((0, 3), np.float32)
    # Only text fields: nibabel adds its own bookkeeping (magic bytes, dtype).
    text = {k: v for k, v in header.items()
            if isinstance(k, str) and isinstance(v, str) and not k.startswith('_') and k != 'endianness'}
    return json.dumps({"count": len(streamlines), "lengths": lengths,
                       "points": [float(v) for v in points.ravel()], "header": text})


def write(path, seed, count):
    rng = np.random.default_rng(seed)
    streamlines = []
    for _ in range(count):
        n = int(rng.integers(2, 40))
        start = rng.uniform(-60, 60, 3)
        steps = rng.normal(0, 0.7, (n, 3))
        streamlines.append((start + np.cumsum(steps, axis=0)).astype(np.float32))
    tck = TckFile(Tractogram(streamlines, affine_to_rasmm=np.eye(4)),
                  header={'command_history': 'tck_reference.py write', 'seed': str(seed)})
    tck.save(path)
    print(as_json(streamlines, {'command_history': 'tck_reference.py write', 'seed': str(seed)}))


def read(path):
    tck = nib.streamlines.load(path)
    print(as_json(list(tck.streamlines), tck.header))


def main():
    if len(sys.argv) == 5 and sys.argv[1] == 'write':
        write(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    elif len(sys.argv) >= 3 and sys.argv[1] == 'read':
        for path in sys.argv[2:]:
            read(path)
    else:
        sys.exit(__doc__)


if __name__ == '__main__':
    main()
