// libFuzzer target for the model importer (models/import/): the input's first byte picks the
// format (the file's extension), the rest is the file. Any input must either import or throw
// InputError; crashes, hangs, leaks and undefined behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "models/import/model_import.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* kExtensions[] = {".obj", ".ply", ".stl", ".gltf", ".dxf", ".ifc", ".off"};
  if (size == 0) return 0;
  const std::string extension = kExtensions[data[0] % 7];
  const std::string path = linetrack::WriteFuzzFile(data + 1, size - 1, extension);
  try {
    linetrack::ImportModel(path, linetrack::ModelImportOptions());
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, path);
  }
  std::filesystem::remove(path);
  return 0;
}
