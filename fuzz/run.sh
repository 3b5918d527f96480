#!/usr/bin/env bash
# Builds the libFuzzer targets (Clang, ASan+UBSan) and runs each one for SECONDS (default 30) from
# its seed corpus. Used by scripts/test.sh for a short smoke run; fuzz/README.md gives long runs.
#   fuzz/run.sh [SECONDS]            build in build-fuzz/, corpora in build-fuzz/corpus/<target>/
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
jobs=$(nproc)
CXX=${CXX:-clang++-14} cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEMBER_FUZZ=ON \
  -DEMBER_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz -j "$jobs" --target fuzz_scene_json fuzz_gltf fuzz_checkpoint fuzz_image ember

corpus=build-fuzz/corpus
mkdir -p "$corpus"/{scene_json,gltf,checkpoint,image}
# Seeds: Ember's own scenes; glTF files of every kind, valid and deliberately broken (Debian's
# assimp-testmodels, the generated showcases, the Khronos samples beside a checkout, the inputs
# fuzzing found crashing: tests/data/fuzz, so each stays fixed under the sanitizers; fuzz/seeds,
# files that reach parts of the loader the others do not, such as sparse accessors, the meshopt,
# Draco and WebP decoders, the KHR material extensions, TEXCOORD_1, COLOR_0 and variants); a real
# checkpoint. Copied, so the fuzzer's new inputs never land in the source tree.
cp scenes/*.json "$corpus/scene_json/"
# Only the folders that exist: find fails on a missing one, and pipefail would end the run (a clone
# without ../shared beside it).
seed_dirs=()
for d in scenes/gltf tests/data/fuzz fuzz/seeds /usr/share/assimp/models/glTF2 ../shared/assets/gltf; do
  if [ -d "$d" ]; then seed_dirs+=("$d"); fi
done
# Under 1 MiB each, as the image seeds below: a larger seed slows every execution. (find rounds a
# size up to its unit before comparing: -size -1024k keeps files of at most 1023 KiB, and the
# -size -2M this replaces kept at most 1 MiB, not the 2 MiB it seemed to say.)
find "${seed_dirs[@]}" \( -name '*.gltf' -o -name '*.glb' \) \
  -size -1024k 2>/dev/null | while read -r f; do cp "$f" "$corpus/gltf/$(echo "$f" | md5sum | cut -c1-16)$(basename "$f" | sed 's/.*\(\.gl[tb]f*\)$/\1/')"; done
ASAN_OPTIONS=detect_leaks=0 build-fuzz/app/ember render scenes/cornell-area.json -o "$corpus/seed.exr" --width 8 \
  --height 6 --spp 2 -q --checkpoint "$corpus/checkpoint/seed.ckpt" 2>/dev/null
# Images: the reference EXRs (written by Mitsuba), Ember's own EXR and PNG outputs, the checker
# texture, a 16-bit PNG, the glTF showcases' half-float EXR environment maps, and a PFM.
cp tests/data/images/*.png scenes/*.png "$corpus/image/"
find tests/data -name '*.exr' -size -1024k | while read -r f; do cp "$f" "$corpus/image/$(echo "$f" | md5sum | cut -c1-16).exr"; done
find scenes -name '*.exr' -size -1024k | while read -r f; do cp "$f" "$corpus/image/$(echo "$f" | md5sum | cut -c1-16).exr"; done
mv "$corpus/seed.exr" "$corpus/image/ember.exr"
printf 'PF\n1 1\n-1.0\n\0\0\200?\0\0\0@\0\0@@' > "$corpus/image/tiny.pfm"

status=0
for target in scene_json gltf checkpoint image; do
  echo "fuzz_$target: ${seconds}s from $(ls "$corpus/$target" | wc -l) seeds"
  # fast_unwind_on_malloc=0: full allocation stacks through libstdc++, which scripts/lsan-suppressions.txt
  # needs to tell OpenImageIO's own leak apart.
  if ! ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:fast_unwind_on_malloc=0:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      LSAN_OPTIONS=suppressions="$PWD/scripts/lsan-suppressions.txt" \
      "build-fuzz/fuzz/fuzz_$target" "$corpus/$target" -max_total_time="$seconds" -timeout=20 \
      -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="build-fuzz/crash-$target-" \
      > "build-fuzz/fuzz_$target.log" 2>&1; then
    echo "fuzz_$target FOUND A PROBLEM:"; tail -40 "build-fuzz/fuzz_$target.log"; status=1
  fi
  grep -E "stat::number_of_executed_units|stat::new_units_added" "build-fuzz/fuzz_$target.log" | sed 's/^/  /'
done
exit $status
