// LDR-FLIP, the perceptual difference evaluator of Andersson, Nilsson, Akenine-Moller, Oskarsson,
// Astrom and Fairchild 2020, "FLIP: A Difference Evaluator for Alternating Images" (Proc. ACM
// Comput. Graph. Interact. Tech. 3(2)). Inputs are display-referred linear RGB in [0, 1] (HDR images
// are tone-mapped first, by the caller); the output is a per-pixel error in [0, 1].
#pragma once

#include "renderer/film.h"

#include <vector>

namespace ember {

struct FlipResult {
  std::vector<float> errorMap;  // width * height, row 0 at the top
  double mean = 0.0;
};

// pixelsPerDegree: observer's angular resolution; 67 is the paper's default (a 0.7 m wide 4K
// monitor seen from 0.7 m).
FlipResult computeFlip(const Image& reference, const Image& test, float pixelsPerDegree = 67.0f);

}  // namespace ember
