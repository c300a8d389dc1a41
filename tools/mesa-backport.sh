#!/usr/bin/env bash
# Unpacks Mesa's lavapipe from Debian bookworm-backports (Mesa 25, which has
# VK_EXT_mesh_shader) into DIR, without installing anything: the mesh-shader generation path
# is then tested on the CPU (`make test` runs render/tests/strand_mesh.rs against it through
# VK_ICD_FILENAMES). The system's own lavapipe (Mesa 22.3 on bookworm) has no mesh shaders.
# Usage: tools/mesa-backport.sh DIR
set -euo pipefail
dir=${1:?usage: tools/mesa-backport.sh DIR}
mkdir -p "$dir/apt/lists/partial" "$dir/apt/cache/archives/partial" "$dir/debs" "$dir/root"
dir=$(cd "$dir" && pwd)
echo "deb http://deb.debian.org/debian bookworm-backports main" > "$dir/apt/sources.list"
apt_options=(
  -o "Dir::Etc::sourcelist=$dir/apt/sources.list" -o "Dir::Etc::sourceparts=-"
  -o "Dir::State::Lists=$dir/apt/lists" -o "Dir::Cache=$dir/apt/cache"
  -o "APT::Get::List-Cleanup=0" -o "Debug::NoLocking=1" -o "APT::Sandbox::User=root"
)
apt-get "${apt_options[@]}" -qq update
cd "$dir/debs"
# Mesa 25 needs a newer libdrm than bookworm's; both come from backports.
apt-get "${apt_options[@]}" -qq download \
  mesa-vulkan-drivers/bookworm-backports libdrm2/bookworm-backports libdrm-amdgpu1/bookworm-backports
for deb in *.deb; do dpkg-deb -x "$deb" "$dir/root"; done
lib="$dir/root/usr/lib/x86_64-linux-gnu"
[ -f "$lib/libvulkan_lvp.so" ] || { echo "mesa-backport: no lavapipe in $(ls)" >&2; exit 1; }
# The package's own ICD file, pointed at the unpacked library.
sed "s#\"library_path\": *\"[^\"]*\"#\"library_path\": \"$lib/libvulkan_lvp.so\"#" \
  "$dir/root/usr/share/vulkan/icd.d/lvp_icd.json" > "$dir/lvp_icd.json"
grep -q "$lib/libvulkan_lvp.so" "$dir/lvp_icd.json"
echo "mesa-backport: $(ls *.deb | tr '\n' ' ')unpacked in $dir"
