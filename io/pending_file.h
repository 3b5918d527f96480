// Atomic output files. Every output (EXR, PNG, checkpoint) goes to a temporary name beside its
// target and is renamed into place, so readers see either no file or the complete one. The
// temporary file being written is remembered, so that a process told to exit at once (a second
// SIGINT/SIGTERM, app/stop_signals.cpp) removes it and leaves nothing half-written. Outputs are
// written by the main thread, one at a time.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace ember {

void setPendingFile(const std::string& path);
void clearPendingFile();
// Async-signal-safe to call and to read: a fixed buffer, "" when nothing is being written.
const char* pendingFile();

// Calls write(temporary path) — a temporary with the target's extension — then renames it to `path`; on
// failure removes it and rethrows.
template <typename WriteFn>
void writeAtomically(const std::string& path, WriteFn write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::string name = ".";  // appended piecewise: GCC 12's -Wrestrict misfires on "." + string
  name.append(target.stem().string()).append(".tmp").append(std::to_string(::getpid()));
  name.append(target.extension().string());
  const fs::path tmp = target.parent_path() / name;
  setPendingFile(tmp.string());
  try {
    write(tmp.string());
    fs::rename(tmp, target);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    clearPendingFile();
    throw;
  }
  clearPendingFile();
}

}  // namespace ember
