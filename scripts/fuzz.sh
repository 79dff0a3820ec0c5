#!/usr/bin/env bash
# Runs every reader's libFuzzer target for a fixed budget.
#   scripts/fuzz.sh [--runs N | --seconds S]    (default: --seconds 60)
# Builds the targets with clang in build-fuzz/, seeds each corpus with small
# valid files made by fibscope itself (and any fuzz/seeds/<format>.* scripts),
# and exits non-zero if any target crashes. Prints executions per target.
set -euo pipefail
cd "$(dirname "$0")/.."

budget=(-max_total_time=60)
case "${1:-}" in
  --runs) budget=(-runs="$2") ;;
  --seconds) budget=(-max_total_time="$2") ;;
  "") ;;
  *) echo "usage: $0 [--runs N | --seconds S]" >&2; exit 2 ;;
esac

command -v clang++ >/dev/null || { echo "fuzz: clang++ is missing (apt-get install clang libclang-rt-14-dev)" >&2; exit 1; }
[ -f build-fuzz/build.ninja ] || CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DFIBSCOPE_FUZZ=ON -DFIBSCOPE_TESTS=OFF -DFIBSCOPE_BENCH=OFF >/dev/null
ninja -C build-fuzz --quiet

# Seeds: tiny phantoms in every writable format, made by the normal build.
# (The fuzz build has the readers only: the seeds come from the main build.)
fibscope=build/fibscope
[ -x "$fibscope" ] || { echo "fuzz: $fibscope is missing: build the main build first (./setup.sh run)" >&2; exit 1; }
seeds=build-fuzz/seeds
rm -rf "$seeds"; mkdir -p "$seeds"/{tck,trk,trx,vtk}
for fmt in tck trk trx; do
  "$fibscope" phantom "$seeds/$fmt/phantom.$fmt" -n 3 --step 8 --min-length 20 --max-length 40 --force >/dev/null 2>&1
done
printf '# vtk DataFile Version 3.0\nseed\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 2 1 0 3 1 1\nLINES 2 6\n2 0 1\n2 2 3\n' \
  > "$seeds/vtk/lines.vtk"
for script in fuzz/seeds/*; do
  [ -f "$script" ] || continue
  fmt=$(basename "$script"); fmt=${fmt%%.*}; fmt=${fmt%%_*}   # fuzz/seeds/<format>[_what].{py,sh}
  mkdir -p "$seeds/$fmt"
  case "$script" in
    *.py) /usr/bin/python3 "$script" "$seeds/$fmt" ;;
    *.sh) bash "$script" "$seeds/$fmt" ;;
  esac
done

status=0
targets=(build-fuzz/fuzz/fuzz_*)
[ -x "${targets[0]}" ] || { echo "fuzz: no fuzz targets were built" >&2; exit 1; }
for target in "${targets[@]}"; do
  [ -x "$target" ] || continue
  name=$(basename "$target"); fmt=${name#fuzz_}
  corpus=build-fuzz/corpus/$fmt
  mkdir -p "$corpus" "build-fuzz/artifacts/$fmt"
  log=build-fuzz/$name.log
  if "$target" "${budget[@]}" -seed=1 -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="build-fuzz/artifacts/$fmt/" "$corpus" "$seeds/$fmt" >"$log" 2>&1; then
    execs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 || true)
    echo "fuzz: $name ok (${execs:-see $log})"
  else
    echo "fuzz: $name FAILED, see $log and build-fuzz/artifacts/$fmt/" >&2
    tail -30 "$log" >&2
    status=1
  fi
done
exit $status
