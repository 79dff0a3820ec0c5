#!/usr/bin/env bash
# fibscope set-up for a fresh Debian 12 machine.
#   ./setup.sh run    install what is missing, build, run the main job
#   ./setup.sh test   install what is missing, build, run every test
# Both are idempotent: installed packages and an up-to-date build are skipped.
set -euo pipefail
cd "$(dirname "$0")"

mode=${1:-run}
case "$mode" in run|test) ;; *) echo "usage: $0 run|test" >&2; exit 2 ;; esac

# Build and run-time packages (Debian 12 names).
packages=(g++ cmake ninja-build pkg-config libgtest-dev libbenchmark-dev libcli11-dev
          nlohmann-json3-dev libzip-dev zlib1g-dev libglm-dev libtinyobjloader-dev libnifti2-dev
          libpugixml-dev liblz4-dev liblzma-dev)
# Vulkan: loader and headers, the shader compiler, lavapipe (Vulkan on the CPU
# where there is no GPU) and the validation layers (on in every GPU test);
# spirv-val checks the task and mesh shaders lavapipe cannot run.
packages+=(libvulkan-dev glslc spirv-tools mesa-vulkan-drivers vulkan-validationlayers)
# The viewer's window and panels (GLFW, Dear ImGui with its backend sources),
# and a virtual X display for it where there is no screen.
packages+=(libglfw3-dev libimgui-dev xvfb xauth)
# Independent references for the tests (nibabel, MRtrix3, Embree for the SVO ray
# tracing, VTK's own writers for the .vtk/.vtp readers) and the fuzzers (clang, libFuzzer).
if [ "$mode" = test ]; then
  packages+=(python3 python3-numpy python3-nibabel mrtrix3 clang libclang-rt-14-dev glslang-tools libembree-dev
            python3-vtk9)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "setup: installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    echo "setup: missing packages; run as root:" >&2
    echo "  apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
fi

jobs=$(nproc)
configure() {  # configure DIR [cmake args...] unless already configured
  local dir=$1; shift
  [ -f "$dir/build.ninja" ] || cmake -S . -B "$dir" -G Ninja "$@" >/dev/null
}

configure build -DCMAKE_BUILD_TYPE=RelWithDebInfo
if [ "$mode" = run ]; then
  # The main job needs the program only; the tests and benchmarks are built
  # by `./setup.sh test`.
  ninja -C build -j "$jobs" --quiet fibscope
else
  ninja -C build -j "$jobs" --quiet
fi

if [ "$mode" = run ]; then
  mkdir -p out
  [ -f out/phantom.tck ] || ./build/fibscope phantom out/phantom.tck --streamlines 20000 --seed 1
  ./build/fibscope info out/phantom.tck
  # The fiblet compression of it, with the report (size, error, speed).
  ./build/fibscope compress out/phantom.tck out/phantom.fbl --report --force
  # The main job: the viewer on the built-in phantom where there is a display;
  # without one, the same renderer headless: the phantom compressed on the fly
  # and drawn by the compute pipeline, lit, to a 1920x1080 PNG (lavapipe runs
  # it on the CPU where there is no GPU).
  if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
    echo "setup: opening the viewer on the built-in phantom (close the window to end)"
    ./build/fibscope view
  else
    echo "setup: no display: rendering headless instead of opening the viewer"
    ./build/fibscope render out/phantom.tck -o out/phantom.png
    echo "setup: wrote out/phantom.png"
  fi
  exit 0
fi

# Tests: the optimised build, then the same tests under ASan + UBSan.
status=0
(cd build && ctest --output-on-failure -j "$jobs" --timeout 600) || status=1
configure build-asan -DCMAKE_BUILD_TYPE=Debug -DFIBSCOPE_SANITIZE=ON -DFIBSCOPE_BENCH=OFF
ninja -C build-asan -j "$jobs" --quiet
lsan_suppressions=$PWD/tests/lsan_suppressions.txt  # third-party Vulkan libraries only
(cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
   LSAN_OPTIONS=suppressions="$lsan_suppressions":print_suppressions=0 \
   ctest --output-on-failure -j "$jobs" --timeout 900) || status=1
# Every reader's fuzzer for a fixed number of runs (deterministic seed).
scripts/fuzz.sh --runs 20000 || status=1
exit $status
