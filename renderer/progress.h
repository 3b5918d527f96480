// Progress on stderr while rendering: on a terminal, a bar redrawn in place with percent, elapsed
// time, ETA and samples/s; otherwise a plain line at every 10%. Runs on its own thread and reads
// one atomic counter, so the render loop pays a single relaxed add per tile.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace ember {

class ProgressReporter {
 public:
  // samplesPerUnit converts work units (pixels) to samples for the rate display.
  ProgressReporter(uint64_t totalUnits, uint64_t samplesPerUnit, bool enabled);
  ~ProgressReporter();
  void advance(uint64_t units) { done_.fetch_add(units, std::memory_order_relaxed); }
  void finish();

 private:
  void run();
  void print(bool final);

  uint64_t total_;
  uint64_t samplesPerUnit_;
  bool enabled_;
  bool terminal_;
  int lastDecile_ = -1;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace ember
