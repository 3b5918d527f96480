#!/usr/bin/env bash
# Renders the default demo scene to out/demo.exr and out/demo.png, building Ember first if needed.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DEMBER_PGO=ON >/dev/null
cmake --build build -j "$(nproc)" --target ember
mkdir -p out
./build/app/ember render "${1:-scenes/demo.json}" -o out/demo.exr --png out/demo.png
echo "wrote out/demo.exr and out/demo.png"
