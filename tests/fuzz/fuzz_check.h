// Shared by the libFuzzer targets: an InputError must name the file it is about (one that does
// not is a finding: the target aborts), and the readers of paths get the input as a file.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "models/errors.h"

namespace linetrack {

inline void ExpectNamesFile(const InputError& error, const std::string& path) {
  if (std::string(error.what()).find(path) == std::string::npos) std::abort();
}

// Writes the input to a file of this process in the temporary folder, named with `suffix` (for
// readers that pick the format by the extension); returns its path.
inline std::string WriteFuzzFile(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("linetrack-fuzz-" + std::to_string(getpid()) + suffix))
                               .string();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), size);
  return path;
}

}  // namespace linetrack
