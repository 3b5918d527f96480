#include "renderer/progress.h"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace ember {

static std::string clock(double seconds) {
  const long s = long(seconds + 0.5);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
  return buf;
}

ProgressReporter::ProgressReporter(uint64_t totalUnits, uint64_t samplesPerUnit, bool enabled)
    : total_(totalUnits == 0 ? 1 : totalUnits),
      samplesPerUnit_(samplesPerUnit),
      enabled_(enabled),
      terminal_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

ProgressReporter::~ProgressReporter() {
  finish();
}

void ProgressReporter::finish() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  print(true);
}

void ProgressReporter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, std::chrono::milliseconds(terminal_ ? 250 : 1000));
    if (!stop_) print(false);
  }
}

void ProgressReporter::print(bool final) {
  const uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
  const double fraction = double(done) / double(total_);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0.0 ? double(done * samplesPerUnit_) / elapsed : 0.0;
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = int(fraction * kWidth);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '.');
    std::fprintf(stderr, "\r[%s] %5.1f%%  %s elapsed  ETA %s  %.2f M samples/s ", bar.c_str(),
                 100.0 * fraction, clock(elapsed).c_str(), clock(eta).c_str(), rate * 1e-6);
    if (final) std::fputc('\n', stderr);
  } else {
    const int decile = int(fraction * 10.0);
    if (decile == lastDecile_ || (final && decile == 10 && lastDecile_ == 10)) return;
    if (!final && decile >= 10) return;  // the 100% line is printed once, by finish()
    lastDecile_ = decile;
    std::fprintf(stderr, "progress: %3d%%  elapsed %s  ETA %s  %.2f M samples/s\n", decile * 10,
                 clock(elapsed).c_str(), clock(eta).c_str(), rate * 1e-6);
  }
  std::fflush(stderr);
}

}  // namespace ember
