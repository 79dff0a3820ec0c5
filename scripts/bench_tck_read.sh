#!/usr/bin/env bash
# .tck read speed, fibscope against nibabel, in one run on one file.
#
#   scripts/bench_tck_read.sh BUILD_DIR [FILE.tck]
#
# Builds nothing: BUILD_DIR must hold bench/tck_read_bench (configure with
# -DFIBSCOPE_BENCH=ON). FILE.tck defaults to $FIBSCOPE_BENCH_TCK, else to
# ${TMPDIR:-/tmp}/fibscope_bench_1g.tck, which the benchmark writes (~1 GB of
# Float32LE random walks) when it is missing. Both readers see the file in
# the page cache. fibscope: best of 3 repetitions of Google Benchmark;
# nibabel: best of 3 nibabel.streamlines.load(path) with /usr/bin/python3.
# GB are 10^9 bytes of file.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 BUILD_DIR [FILE.tck]" >&2
  exit 2
fi
bench=$1/bench/tck_read_bench
[ -x "$bench" ] || { echo "$bench not found: build with -DFIBSCOPE_BENCH=ON" >&2; exit 1; }
file=${2:-${FIBSCOPE_BENCH_TCK:-${TMPDIR:-/tmp}/fibscope_bench_1g.tck}}
python=/usr/bin/python3
"$python" -c 'import nibabel' 2>/dev/null || { echo "$python has no nibabel (apt-get install python3-nibabel)" >&2; exit 1; }

json=$(mktemp "${TMPDIR:-/tmp}/bench_tck_read.XXXXXX.json")
trap 'rm -f "$json"' EXIT

# Without the file the benchmark generates it at the default path.
if [ -e "$file" ]; then
  FIBSCOPE_BENCH_TCK=$file "$bench" --benchmark_repetitions=3 --benchmark_out="$json" --benchmark_out_format=json >&2
else
  [ "$file" = "${TMPDIR:-/tmp}/fibscope_bench_1g.tck" ] || { echo "$file does not exist" >&2; exit 1; }
  env -u FIBSCOPE_BENCH_TCK "$bench" --benchmark_repetitions=3 --benchmark_out="$json" --benchmark_out_format=json >&2
fi

"$python" - "$file" "$json" <<'PY'
import json, os, sys, time
import nibabel as nib

path, results = sys.argv[1], sys.argv[2]
size = os.path.getsize(path)
runs = [b for b in json.load(open(results))["benchmarks"] if b.get("run_type") == "iteration"]
fibscope = max(b["bytes_per_second"] for b in runs) / 1e9

best = float("inf")
for _ in range(3):
    start = time.perf_counter()
    tck = nib.streamlines.load(path)
    best = min(best, time.perf_counter() - start)
    count = len(tck.streamlines)
    del tck
nibabel = size / best / 1e9

print(f"file:     {path} ({size / 1e9:.3f} GB, {count} streamlines)")
print(f"fibscope: {fibscope:.2f} GB/s (best of 3)")
print(f"nibabel:  {nibabel:.2f} GB/s (best of 3, {best:.2f} s per load)")
print(f"ratio:    {fibscope / nibabel:.1f}x")
PY
