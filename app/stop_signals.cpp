#include "app/stop_signals.h"

#include "io/pending_file.h"

#include <unistd.h>

#include <csignal>

namespace ember::cli {

namespace {

std::atomic<bool> gStop{false};
std::atomic<int> gSignal{0};

// Only async-signal-safe calls here: atomics, unlink, write, _exit.
void onSignal(int sig) {
  if (gStop.exchange(true)) {
    const char* tmp = pendingFile();
    if (tmp[0] != '\0') ::unlink(tmp);
    static const char msg[] = "\nember: second signal: exiting at once\n";
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    ::_exit(128 + sig);
  }
  gSignal.store(sig);
  static const char msg[] = "\nember: stopping after the tiles in flight (a second signal exits at once)\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
}

}  // namespace

StopSignals::StopSignals() {
  struct sigaction sa = {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// The handlers stay until the process exits: a second signal during the exit that follows the
// render (writing outputs, tearing down) must still exit at once with 128 + its number, not die
// of the default action.
StopSignals::~StopSignals() = default;

const std::atomic<bool>& StopSignals::flag() const {
  return gStop;
}

int StopSignals::signal() const {
  return gSignal.load();
}

}  // namespace ember::cli
