#include "app/cli_common.h"

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {

Pose3Dof ParsePrior(const std::string& text, const std::string& flag) {
  std::stringstream in(text);
  std::string field;
  double values[3];
  int n = 0;
  while (std::getline(in, field, ',')) {
    if (n >= 3) throw InputError(flag + ": expected X,Y,HEADING_DEG, got '" + text + "'");
    try {
      size_t used = 0;
      values[n] = std::stod(field, &used);
      if (used != field.size() || !std::isfinite(values[n])) throw std::invalid_argument(field);
    } catch (const std::exception&) {
      throw InputError(flag + ": not a finite number: '" + field + "' in '" + text + "'");
    }
    ++n;
  }
  if (n != 3) throw InputError(flag + ": expected X,Y,HEADING_DEG, got '" + text + "'");
  return {values[0], values[1], DegToRad(values[2])};
}

std::vector<double> ParseNumbers(const std::string& text, int count, const std::string& flag) {
  std::stringstream in(text);
  std::string field;
  std::vector<double> values;
  while (std::getline(in, field, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(field, &used));
      if (used != field.size() || !std::isfinite(values.back())) throw std::invalid_argument(field);
    } catch (const std::exception&) {
      throw InputError(flag + ": not a finite number: '" + field + "' in '" + text + "'");
    }
  }
  if (static_cast<int>(values.size()) != count || (!text.empty() && text.back() == ',')) {
    throw InputError(flag + ": expected " + std::to_string(count) +
                     " comma-separated numbers, got '" + text + "'");
  }
  return values;
}

void CheckRange(double value, double lo, double hi, const std::string& flag) {
  if (!std::isfinite(value) || value < lo || value > hi) {
    std::ostringstream msg;
    msg << flag << ": " << value << " is outside [" << lo << ", " << hi << "]";
    throw InputError(msg.str());
  }
}

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << content;
    out.flush();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw InputError(path + ": cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path + ": cannot write the file");
  }
}

CLI::App* BenchGroup(CLI::App& cli) {
  const auto found = cli.get_subcommands([](CLI::App* s) { return s->get_name() == "bench"; });
  if (!found.empty()) return found.front();
  CLI::App* bench = cli.add_subcommand(
      "bench", "Benchmarks: accuracy and speed figures on this machine (see docs/)");
  bench->require_subcommand(1);
  return bench;
}

void EnsureDirectory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(dir + ": cannot create the output folder");
  }
}

}  // namespace linetrack::app
