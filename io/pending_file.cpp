#include "io/pending_file.h"

#include <cstring>

namespace ember {

namespace {
char gPending[4096] = {0};
}

void setPendingFile(const std::string& path) {
  if (path.size() >= sizeof gPending) return;  // too long to remember: not removed on a hard exit
  std::memcpy(gPending, path.c_str(), path.size() + 1);
}

void clearPendingFile() {
  gPending[0] = '\0';
}

const char* pendingFile() {
  return gPending;
}

}  // namespace ember
