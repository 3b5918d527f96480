// The calling thread's instance of a kernel's wave state (its rows, packets and scratch), made on
// the thread's first tile and kept for the thread's life: a tile, and so the hot path, allocates
// nothing. Each kernel instantiates it with its own wave type.
#pragma once

#include <memory>

namespace ember {

template <class Wave>
Wave& threadWave() {
  thread_local std::unique_ptr<Wave> wave;
  if (!wave) wave = std::make_unique<Wave>();
  return *wave;
}

}  // namespace ember
