#!/usr/bin/env bash
# Installs the build and test dependencies from Debian 12 packages (needs root or sudo).
set -euo pipefail
packages=(
  build-essential cmake ninja-build ccache clang git curl ca-certificates
  libeigen3-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev libnanoflann-dev gnuplot-nox libboost1.81-dev liblo-dev pkgconf
  chromium fonts-liberation
)
# Installed without their recommends. blender: the BVH output is opened in Blender's importer by
# a test (tests/viewers); on a Debian 12 build machine with the packages above about 150 packages,
# 160 MB to download and 620 MB installed.
lean_packages=(blender)
is_installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
missing=()
for p in "${packages[@]}"; do
  is_installed "$p" || missing+=("$p")
done
missing_lean=()
for p in "${lean_packages[@]}"; do
  is_installed "$p" || missing_lean+=("$p")
done
if [ ${#missing[@]} -eq 0 ] && [ ${#missing_lean[@]} -eq 0 ]; then
  echo "install-deps: all packages present" >&2
  exit 0
fi
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "install-deps: installing ${missing[*]} ${missing_lean[*]}" >&2
"${sudo_cmd[@]}" apt-get update -qq
if [ ${#missing[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >&2
fi
if [ ${#missing_lean[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing_lean[@]}" >&2
fi
