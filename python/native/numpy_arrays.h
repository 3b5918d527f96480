// numpy arrays that own the renderer's pixel vectors: moved into the array's capsule, never copied.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <vector>

namespace ember::python {

// Shape (height, width) for one channel, else (height, width, channels), float32.
inline nanobind::object pixelArray(std::vector<float>&& pixels, int height, int width, size_t channels) {
  auto* owned = new std::vector<float>(std::move(pixels));
  nanobind::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  const size_t shape[3] = {size_t(height), size_t(width), channels};
  return nanobind::ndarray<nanobind::numpy, float>(owned->data(), channels == 1 ? 2 : 3, shape, owner).cast();
}

// A C-contiguous float32 array's pixels as rows of `channels` floats (copied: the array is Python's).
using FloatArray = nanobind::ndarray<const float, nanobind::c_contig, nanobind::device::cpu>;

}  // namespace ember::python
