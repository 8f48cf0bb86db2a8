#!/usr/bin/env bash
# Installs the Debian packages clothcd needs; does nothing when they are all present.
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libeigen3-dev libtbb-dev libfmt-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libgmp-dev
  clang clang-format libclang-rt-14-dev
  python3-matplotlib
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest python3-meshio
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "clothcd setup: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "clothcd setup: run as root or install sudo" >&2; exit 1; }
  sudo="sudo"
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
