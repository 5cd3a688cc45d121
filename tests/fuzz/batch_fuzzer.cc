// libFuzzer target for the cases of a `localize --batch` file (app/localize_io.h): each line that
// is valid JSON must give a case or an InputError (the command names the file and line in it);
// any other exception, a crash, a hang, a leak or undefined behaviour is a finding.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "app/localize_io.h"
#include "models/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
  for (std::string row; std::getline(lines, row);) {
    const nlohmann::json json = nlohmann::json::parse(row, nullptr, false);
    if (json.is_discarded()) continue;  // "not valid JSON" for the command
    try {
      linetrack::app::ParseBatchCase(json, "fuzz-dir");
    } catch (const linetrack::InputError&) {
    }
  }
  return 0;
}
