#!/usr/bin/env bash
# Install the Debian 12 packages accretion needs (only those missing).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libtbb-dev libglm-dev
  libopenexr-dev libpng-dev libfreetype-dev libopenimageio-dev openimageio-tools
  catch2 libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libpcg-cpp-dev libeigen3-dev libbenchmark-dev gnuplot-nox clang parallel fonts-dejavu-core
  python3 python3-venv locales
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [[ $(id -u) -eq 0 ]] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
