// libFuzzer target: the checkpoint reader (checkpoint/checkpoint_file.cpp), which must reject any
// file that is not a complete, uncorrupted checkpoint with an InputError. The checksum rejects
// almost every mutation at once, so inputs whose checksum is wrong are also tried with it
// repaired: that is what reaches the header and size checks behind it.
#include "checkpoint/checkpoint_file.h"
#include "fuzz/fuzz_input.h"

#include <xxhash.h>

#include <cstring>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = ember::fuzz::inputFile(".ckpt");
  ember::fuzz::writeInput(path, data, size);
  ember::fuzz::expectOnlyInputErrors([&] { ember::readCheckpoint(path); });
  if (size >= 8) {
    std::vector<uint8_t> fixed(data, data + size);
    const uint64_t sum = XXH3_64bits(fixed.data(), size - 8);
    std::memcpy(fixed.data() + size - 8, &sum, 8);
    ember::fuzz::writeInput(path, fixed.data(), size);
    ember::fuzz::expectOnlyInputErrors([&] { ember::readCheckpoint(path); });
  }
  return 0;
}
