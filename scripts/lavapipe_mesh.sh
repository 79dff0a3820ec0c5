#!/usr/bin/env bash
# A lavapipe that has VK_EXT_mesh_shader (Mesa 25 from Debian's
# bookworm-backports; bookworm's Mesa 22.3 has none), unpacked into a
# private folder with apt's own client: nothing is installed or changed
# system-wide, so other tests keep the system's driver. It lets the mesh
# pipelines' device tests run (on the CPU) where there is no GPU:
#
#   scripts/lavapipe_mesh.sh DIR            # once: download and unpack into DIR
#   eval "$(scripts/lavapipe_mesh.sh DIR --env)"
#   build/tests/fibscope_unit_tests --gtest_filter='DeviceMeshPipeline.*:GpuMeshSupport.*:GpuCliMeshPipeline.*'
#
# A CPU rasteriser is not a GPU: it checks the shaders, the pipeline and the
# synchronisation under the validation layers, not speed or a vendor's
# driver.
set -euo pipefail
dir=$(realpath -m "${1:?folder}")
lib=$dir/root/usr/lib/x86_64-linux-gnu
if [ "${2:-}" = --env ]; then
  echo "export VK_DRIVER_FILES=$dir/lvp_icd.json VK_ICD_FILENAMES=$dir/lvp_icd.json LD_LIBRARY_PATH=$lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
  exit 0
fi
mkdir -p "$dir/lists/partial" "$dir/cache/archives/partial" "$dir/debs"
echo "deb http://deb.debian.org/debian bookworm-backports main" > "$dir/sources.list"
apt_opts=(-o "Dir::Etc::SourceList=$dir/sources.list" -o Dir::Etc::SourceParts=/nonexistent
          -o "Dir::State::Lists=$dir/lists" -o "Dir::Cache=$dir/cache")
apt-get "${apt_opts[@]}" update
# The driver and the libdrm it needs (newer than bookworm's); LLVM 15 is
# bookworm's own.
(cd "$dir/debs" && apt-get "${apt_opts[@]}" download mesa-vulkan-drivers libdrm2 libdrm-amdgpu1)
for deb in "$dir"/debs/*.deb; do dpkg -x "$deb" "$dir/root"; done
# The package's manifest names the library alone; LD_LIBRARY_PATH finds it.
cp "$dir/root/usr/share/vulkan/icd.d/lvp_icd.json" "$dir/lvp_icd.json"
echo "unpacked into $dir; then: eval \"\$($0 $dir --env)\""
