#!/bin/sh
# Writes small valid TRX zips into DIR as a seed corpus for fuzz_trx:
#   fuzz/seeds/trx_seeds.sh DIR
set -e
dir=${1:?usage: trx_seeds.sh DIR}
ref="$(dirname "$0")/../../tests/tools/trx_reference.py"
mkdir -p "$dir"
/usr/bin/python3 "$ref" make "$dir/stored.trx" --layout stored --streamlines 3 --data --groups >/dev/null
/usr/bin/python3 "$ref" make "$dir/deflated.trx" --layout deflated --streamlines 3 --positions float16 --data >/dev/null
/usr/bin/python3 "$ref" make "$dir/mixed.trx" --layout mixed --streamlines 4 --offsets int32 --no-sentinel --groups >/dev/null
/usr/bin/python3 "$ref" make "$dir/folder.trx" --layout stored --streamlines 2 --positions float64 --top-folder t >/dev/null
/usr/bin/python3 "$ref" make "$dir/empty.trx" --layout stored --streamlines 0 >/dev/null
