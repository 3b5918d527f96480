// A render's accumulation state on disk, so that a killed or interrupted render can resume and end
// bit-identical to one that never stopped (docs/distributed.md describes the workflow).
//
// Layout (little-endian):
//   "EMBERCKP"              8 bytes, magic
//   u32 format version      kCheckpointFormat
//   u32 n, then n bytes     header: JSON with the render's identity (checkpoint/render_identity.h),
//                           the sample range (first sample, target spp, pass size, passes done),
//                           the output path and the Ember version
//   sums                    width * height * 3 doubles (Film::sums)
//   sums of squares         width * height * 3 doubles
//   counts                  width * height u32
//   AOV sums                width * height * AovLayout(aovs).channels doubles (Film::aovSums), the
//                           set named in the header's "aovs"
//   budgets                 width * height u32 (Film::budgets) when the header's "budgets" is true
//   u64 XXH3-64             of every byte before it
// A file is written to a temporary name beside the target, flushed to disk, then renamed over it:
// a reader, or a render killed at any moment, sees the previous checkpoint or the new one, whole.
#pragma once

#include "checkpoint/render_identity.h"
#include "renderer/film.h"

#include <cstdint>
#include <string>

namespace ember {

inline constexpr uint32_t kCheckpointFormat = 2;

struct Checkpoint {
  RenderIdentity identity;
  uint64_t firstSample = 0;
  int spp = 0;      // the render's target
  int passSpp = 1;  // samples per pixel per pass
  int passes = 0;   // completed passes the film holds
  std::string output;
  std::string emberVersion;
  // Adaptive sampling's per-pixel target and pilot (renderer/render.h), 0 when the render is not
  // adaptive: a resumed render keeps them, so that it sets the same budgets.
  double adaptiveTarget = 0.0;
  int adaptivePilotSpp = 0;
  Film film{1, 1};
};

void writeCheckpoint(const std::string& path, const Checkpoint& checkpoint);
// Reads and checks a checkpoint; InputError naming the file for anything that is not a complete,
// uncorrupted Ember checkpoint of this format.
Checkpoint readCheckpoint(const std::string& path);

}  // namespace ember
