#!/usr/bin/env bash
# Everything one lent-GPU session must show, in one command (the device's
# time is counted from its start): issue 14's filter figure, issue 17's
# bundling tables and figure models, issue 15's figure 19, then the GPU
# tests with the validation layers on the NVIDIA driver, in 8 shards at
# once. Each part runs under its own time limit and the whole under BUDGET
# seconds; results are packed into OUT/results.tar.gz after each part, so
# what finished comes back even when a later part is cut off.
#
#   here:   ninja -C build && scripts/device_prepare.sh build
#   device (carry .gl): . .gl/env.sh; scripts/device_run.sh "$OUT" [paper|small]
#   try it here first:  FIBSCOPE=build/fibscope UNIT_TESTS=build/tests/fibscope_unit_tests \
#                       scripts/device_run.sh /tmp/dr small
set -uo pipefail
out=${1:?output folder}
scale=${2:-paper}
budget=${BUDGET:-420}
export FIBSCOPE=${FIBSCOPE:-.gl/bin/fibscope}
unit_tests=${UNIT_TESTS:-.gl/bin/fibscope_unit_tests}
start=$(date +%s)
res=$out/results
mkdir -p "$res"
log=$out/log.txt
left() { echo $((budget - ($(date +%s) - start))); }
pack() { tar -C "$out" -czf "$out/results.tar.gz" results; }
part() {  # part NAME SECONDS COMMAND...: runs COMMAND with at most SECONDS (and what the budget has left)
  local name=$1 limit=$2; shift 2
  local l; l=$(left)
  [ "$l" -lt "$limit" ] && limit=$l
  if [ "$limit" -le 5 ]; then echo "== $name: skipped, the budget is spent" | tee -a "$log"; return; fi
  echo "== $name (at most ${limit} s, $(($(date +%s) - start)) s in)" | tee -a "$log"
  local t0; t0=$(date +%s)
  timeout "$limit" "$@" >> "$log" 2>&1
  echo "== $name: exit $? after $(($(date +%s) - t0)) s" | tee -a "$log"
  pack
}

{ date -u; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1; git log -1 --format='commit %H' 2>/dev/null; } \
  > "$res/machine.txt"
"$FIBSCOPE" gpu-info >> "$res/machine.txt" 2>&1

if [ "$scale" = small ]; then
  part filter 120 scripts/device_filter.sh "$res/filter" 2000
  part bundle 200 scripts/device_bundle.sh "$res/bundle" small
  part figure19 200 env SAMPLE=2 FRAMES=20 METHODS=none,compute,raycast scripts/tubes_figure19.sh "$res/figure19" small
  tests='GpuFiberFilter*'
else
  part filter 100 scripts/device_filter.sh "$res/filter" 1000000
  part bundle 110 env TIMEOUT=40 scripts/device_bundle.sh "$res/bundle" paper
  part figure19 200 env TIMEOUT=30 SAMPLE_D=20 scripts/tubes_figure19.sh "$res/figure19" full
  tests='Gpu*'
fi

# The GPU tests (validation layers on: a validation error fails a test) in
# 8 shards at once; a shard's log is kept when it fails.
gpu_tests() {
  local pids=() n=8
  for i in $(seq 0 $((n - 1))); do
    GTEST_TOTAL_SHARDS=$n GTEST_SHARD_INDEX=$i "$unit_tests" --gtest_filter="$tests" --gtest_brief=1 \
      > "$res/tests_$i.txt" 2>&1 &
    pids+=($!)
  done
  local status=0
  for p in "${pids[@]}"; do wait "$p" || status=1; done
  grep -h -E '^\[  (PASSED|FAILED|SKIPPED) ' "$res"/tests_*.txt | sort | uniq -c
  return $status
}
export unit_tests tests res
part tests "$(left)" bash -c "$(declare -f gpu_tests); gpu_tests"
pack
tail -40 "$log"
