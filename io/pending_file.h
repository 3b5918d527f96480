// The temporary file an output is being written to right now, if any: every output (EXR, PNG,
// checkpoint) goes to a temporary name and is renamed into place, and a process told to exit at
// once (a second SIGINT/SIGTERM, app/stop_signals.cpp) removes this file so that nothing
// half-written is left. Outputs are written by the main thread, one at a time.
#pragma once

#include <string>

namespace ember {

void setPendingFile(const std::string& path);
void clearPendingFile();
// Async-signal-safe to call and to read: a fixed buffer, "" when nothing is being written.
const char* pendingFile();

}  // namespace ember
