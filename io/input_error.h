// The one exception type for bad input: its message names the file and the place in it, e.g.
// "scenes/x.json: shapes[3].radius: expected a number > 0". The command line prints it and exits
// non-zero before any output file is written.
#pragma once

#include <stdexcept>
#include <string>

namespace ember {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ember
