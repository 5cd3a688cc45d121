// libFuzzer target for the model importer (models/import/): the input's first byte picks the
// format (the file's extension), the rest is the file. Any input must either import or throw
// InputError; crashes, hangs, leaks and undefined behaviour are findings.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "models/errors.h"
#include "models/import/model_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* kExtensions[] = {".obj", ".ply", ".stl", ".gltf", ".dxf", ".ifc", ".off"};
  if (size == 0) return 0;
  const std::string extension = kExtensions[data[0] % 7];
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("linetrack-import-fuzz-" + std::to_string(getpid()) + extension))
                               .string();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    linetrack::ImportModel(path, linetrack::ModelImportOptions());
  } catch (const linetrack::InputError&) {
  }
  std::filesystem::remove(path);
  return 0;
}
