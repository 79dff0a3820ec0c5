#!/usr/bin/env bash
# Prepares .gl/ (git-ignored) for running fibscope on a lent GPU machine
# (the `device` tool: an NVIDIA H100/H200 in an Ubuntu container with the
# NVIDIA driver but no Vulkan loader): Debian's Vulkan loader and glvnd
# packages to unpack there, the stripped fibscope binary and unit tests with
# their shared libraries, the validation layer, and env.sh, which a device
# command sources first:
#
#   scripts/device_prepare.sh build       # here, after building build/
#   device run (carry .gl): . .gl/env.sh; .gl/bin/fibscope gpu-info; ...
#
# The tests spawn the CLI at its build path and read tests/tools: env.sh
# links /work/main/build/fibscope and /work/main/tests to the carried copies.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo '/.gl/' >> .git/info/exclude
rm -rf .gl && mkdir -p .gl/bin .gl/lib .gl/layers /tmp/amd64/partial
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
apt-get $o update -qq
(cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 2>/dev/null)
strip -o .gl/bin/fibscope "$build/fibscope"
[ -x "$build/tests/fibscope_unit_tests" ] && strip -o .gl/bin/fibscope_unit_tests "$build/tests/fibscope_unit_tests"
# Every shared library the binaries need except the C/C++ runtime (the
# container's newer glibc and libstdc++ run binaries built on Debian 12).
for bin in .gl/bin/*; do
  ldd "$bin" | awk '$3 ~ /^\// {print $3}'
done | sort -u | grep -v -E '/(libc|libm|libstdc\+\+|libgcc_s|libdl|libpthread|librt|libvulkan)\.so' |
  while read -r lib; do cp -L "$lib" .gl/lib/; done
cp /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so .gl/lib/
sed 's#"library_path": "libVkLayer_khronos_validation.so"#"library_path": "../lib/libVkLayer_khronos_validation.so"#' \
  /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json > .gl/layers/VkLayer_khronos_validation.json
# The tree that travels holds 64 MiB at most (the repository's files too):
# the binaries and libraries travel xz-packed (the unit tests need Embree's
# 42 MB) and env.sh unpacks them there.
tar -C .gl -cf - bin lib layers | xz -T0 -6 > .gl/pack.tar.xz
rm -rf .gl/bin .gl/lib .gl/layers
cat > .gl/env.sh <<'ENV'
# Sourced first by every device command (from the repository root there).
[ -f .gl/pack.tar.xz ] && xz -dc .gl/pack.tar.xz | tar -C .gl -xf - && rm .gl/pack.tar.xz
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export LD_LIBRARY_PATH=$PWD/.gl/lib:${LD_LIBRARY_PATH:-}
export VK_LAYER_PATH=$PWD/.gl/layers
mkdir -p /work/main/build && ln -sf "$PWD/.gl/bin/fibscope" /work/main/build/fibscope
ln -sfn "$PWD/tests" /work/main/tests 2>/dev/null || true
ENV
du -sh .gl
