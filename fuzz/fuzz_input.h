// Shared by the fuzz targets: the loaders read files, so each input is written to a file of its
// own in the temporary folder first, and only InputError — the loaders' one way of rejecting
// bad input — is an acceptable outcome besides success. Any other exception, a crash, or an
// ASan/UBSan report is a finding.
#pragma once

#include "io/input_error.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

namespace ember::fuzz {

inline std::string inputFile(const char* extension) {
  return (std::filesystem::temp_directory_path() / ("ember_fuzz_" + std::to_string(::getpid()) + extension))
      .string();
}

inline void writeInput(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

// Runs `body`; InputError is the expected rejection, anything else aborts (a finding).
template <typename Body>
void expectOnlyInputErrors(Body body) {
  try {
    body();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz finding: exception other than InputError: %s\n", e.what());
    std::abort();
  }
}

}  // namespace ember::fuzz
