// The steps a path tracer takes per bounce, as the batched kernels run them one after another for
// a whole wave (packet/wave_integrator.cpp), and a clock that charges the time between its
// marks to them: `ember bench --phases` reports where a render's time goes by step, the measure
// the structure-of-arrays plan (docs/architecture.md) predicts and checks its stages with.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace ember {

enum class PathPhase : uint8_t {
  Camera,        // pixel numbers, camera rays, paths started, and the film when they end
  TraceClosest,  // the closest-hit batch through Embree and the shapes' callbacks
  Arrival,       // hits grouped by geometry, hit records, emission, absorption
  LightChoice,   // the light choice's numbers and the choice
  LightSamples,  // the chosen lights' samples
  NextEvent,     // BSDF values, MIS weights, shadow rays, the BSDF samples' inputs
  BsdfSamples,   // the BSDF samples' numbers and the samples
  Continuation,  // throughput, Russian roulette, next rays
  TraceShadows,  // the shadow batch, and the contributions of the unoccluded rays
  Count
};

inline constexpr size_t kPathPhases = size_t(PathPhase::Count);
inline constexpr std::array<std::string_view, kPathPhases> kPathPhaseNames = {
    "camera",     "trace_closest", "arrival",      "light_choice",  "light_samples",
    "next_event", "bsdf_samples",  "continuation", "trace_shadows",
};

// Nanoseconds from `from` to `to` on the steady clock: what PhaseClock and traceTimed
// (packet/timed_trace.h) add up.
inline uint64_t nanosecondsBetween(std::chrono::steady_clock::time_point from,
                                   std::chrono::steady_clock::time_point to) {
  return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(to - from).count());
}

// Adds the time since the previous mark (or since construction) to the phase named. Off, it reads
// no clock: a branch per phase and bounce, nothing per ray.
class PhaseClock {
 public:
  PhaseClock(bool on, std::array<uint64_t, kPathPhases>& totals) : on_(on), totals_(totals) {
    if (on_) last_ = Clock::now();
  }
  void mark(PathPhase phase) {
    if (!on_) return;
    const Clock::time_point now = Clock::now();
    totals_[size_t(phase)] += nanosecondsBetween(last_, now);
    last_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool on_;
  std::array<uint64_t, kPathPhases>& totals_;
  Clock::time_point last_{};
};

}  // namespace ember
