// SIGINT and SIGTERM during a render: the first asks the render to stop (it finishes the tiles in
// flight, takes the interrupted pass back, writes the image and checkpoint of the completed
// passes, and exits with 128 + the signal's number: 130 or 143). A second signal exits at once,
// removing a half-written checkpoint's temporary file, so the last complete checkpoint is intact.
#pragma once

#include <atomic>

namespace ember::cli {

class StopSignals {
 public:
  StopSignals();   // installs the handlers
  ~StopSignals();  // leaves them installed until the process exits
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  const std::atomic<bool>& flag() const;
  int signal() const;  // the first signal received, 0 if none
};

}  // namespace ember::cli
