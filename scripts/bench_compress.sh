#!/usr/bin/env bash
# `fibscope compress` end to end (both passes, file in the page cache, both
# cores) on phantoms of two sizes: throughput, bytes per point, error, and
# peak resident memory, which must not grow with the input.
#
#   scripts/bench_compress.sh BUILD_DIR DATA_DIR [SMALL_FIBERS LARGE_FIBERS]
#
# Writes DATA_DIR/small.tck and DATA_DIR/large.tck with `fibscope phantom`
# (0.1 mm, seed 21; defaults 190000 and 760000 fibers, about 2 GB and 8 GB)
# unless they exist, then compresses each 1 + RUNS times (default RUNS=3;
# the first run warms the page cache) and reports the median run by
# throughput, with the largest peak RSS of the runs (/usr/bin/time -v). The
# large file needs ~9 GB of disk and is read twice, so it should fit in the
# page cache (or the figure is disk speed).
set -euo pipefail
if [ $# -ne 2 ] && [ $# -ne 4 ]; then
  echo "usage: $0 BUILD_DIR DATA_DIR [SMALL_FIBERS LARGE_FIBERS]" >&2
  exit 2
fi
fibscope=$1/fibscope
data=$2
small=${3:-190000}
large=${4:-760000}
[ -x "$fibscope" ] || { echo "$fibscope not found" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "/usr/bin/time not found (apt-get install time)" >&2; exit 1; }
mkdir -p "$data"
for pair in "small:$small" "large:$large"; do
  name=${pair%%:*}
  n=${pair#*:}
  [ -e "$data/$name.tck" ] || "$fibscope" phantom "$data/$name.tck" -n "$n" --seed 21 >/dev/null
done

printf '%-10s %14s %12s %8s %12s %10s %10s %10s %12s\n' input points "tck bytes" "B/pt" "M points/s" "max um" "mean um" "seconds" "peak RSS MB"
for name in small large; do
  in=$data/$name.tck
  out=$data/$name.fbl
  "$fibscope" compress "$in" "$out" --force >/dev/null
  log=$(mktemp)
  for run in $(seq "${RUNS:-3}"); do
    /usr/bin/time -v "$fibscope" compress "$in" "$out" --force --json >"$log.$run.json" 2>"$log.$run"
  done
  /usr/bin/python3 - "$log" "${RUNS:-3}" "$name" "$(stat -c %s "$in")" <<'PY'
import json, re, sys
log, runs, name, size = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
reports = [json.load(open('%s.%d.json' % (log, r))) for r in range(1, runs + 1)]
rss = max(int(re.search(r'Maximum resident set size \(kbytes\): (\d+)', open('%s.%d' % (log, r)).read()).group(1))
          for r in range(1, runs + 1))
reports.sort(key=lambda r: r['points_per_second'])
r = reports[len(reports) // 2]
rates = ', '.join('%.1f' % (x['points_per_second'] / 1e6) for x in reports)
print('%-10s %14d %12d %8.3f %12.1f %10.2f %10.2f %10.2f %12.1f   (runs: %s)' % (
    name, r['points'], size, r['bytes_per_point'], r['points_per_second'] / 1e6,
    r['error_um']['max'], r['error_um']['mean'], r['seconds']['total'], rss / 1024, rates))
PY
  rm -f "$log" "$log".*
done
