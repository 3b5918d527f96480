#!/usr/bin/env bash
# Installs the Debian 12 packages Ember builds and tests against, skipping any already present.
# Used by the README commands and by .ci/run. Needs root (or sudo) for apt-get. Then Intel Open Image
# Denoise for `ember render --denoise`: Debian 12 packages none, so the PyPI wheel pyoidn (which ships
# libOpenImageDenoise.so.2 and its CPU device) goes into the repository's .venv, where ember looks
# (denoise/oidn_library.h). Without network that step only warns: --denoise then says what it needs.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libhwy-dev libxxhash-dev libopenexr-dev libimath-dev
  libtinygltf-dev libstb-dev libopenimageio-dev libmeshoptimizer-dev libdraco-dev libwebp-dev libglm-dev libtbb-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libbenchmark-dev libfmt-dev assimp-testmodels
  libopenmpi-dev openmpi-bin clang-14 libclang-rt-14-dev python3-venv
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "setup-deps: installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

venv="$(cd "$(dirname "$0")/.." && pwd)/.venv"
if ! compgen -G "$venv/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2" >/dev/null; then
  # --no-deps: ember loads the library alone; pyoidn's own Python bindings (numpy, cffi) are not needed.
  { [ -x "$venv/bin/pip" ] || python3 -m venv "$venv"; } &&
    "$venv/bin/pip" install -q --disable-pip-version-check --no-deps pyoidn==2.5.1 ||
    echo "setup-deps: warning: could not install pyoidn into $venv (no network?); ember render --denoise will not work" >&2
fi
