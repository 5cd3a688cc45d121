// Errors for bad input. Expected failures (no pose, no pattern) are results, not exceptions;
// an InputError means a file, line or field is at fault, and its message names it.
#pragma once

#include <stdexcept>
#include <string>

namespace linetrack {

// Bad input: the message is one line naming the file (and line or field) and what is wrong.
// app/ prints it on stderr and exits with code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "path:line: what" (line omitted when <= 0).
inline std::string Located(const std::string& path, int line, const std::string& what) {
  return line > 0 ? path + ":" + std::to_string(line) + ": " + what : path + ": " + what;
}

}  // namespace linetrack
