#!/usr/bin/env bash
# Installs the Debian 12 packages Ember builds and tests against, skipping any already present.
# Used by the README commands and by .ci/run. Needs root (or sudo) for apt-get.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libhwy-dev libxxhash-dev libopenexr-dev libimath-dev
  libtinygltf-dev libstb-dev libopenimageio-dev libmeshoptimizer-dev libdraco-dev libwebp-dev libglm-dev libtbb-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libbenchmark-dev libfmt-dev assimp-testmodels
  libopenmpi-dev openmpi-bin clang-14 libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "setup-deps: installing ${missing[*]}" >&2
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
