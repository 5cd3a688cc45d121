// The cases of a `localize --batch` file (declared in app/localize_io.h): apart from the rest of
// localize's files so that the batch fuzzer (tests/fuzz/batch_fuzzer.cc) can build it alone.
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "app/localize_io.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {
namespace {

std::string Resolve(const std::string& path, const std::string& base_dir) {
  if (path.empty() || path[0] == '/' || base_dir.empty()) return path;
  return (std::filesystem::path(base_dir) / path).lexically_normal().string();
}

template <typename T>
T Required(const nlohmann::json& json, const char* key) {
  if (!json.contains(key)) throw InputError(std::string("missing key \"") + key + "\"");
  try {
    return json.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(std::string("key \"") + key + "\" has the wrong type");
  }
}

double FiniteNumber(const nlohmann::json& json, const char* key) {
  const nlohmann::json& v = json.contains(key) ? json.at(key) : nlohmann::json();
  if (!v.is_number()) {
    throw InputError(std::string(json.contains(key) ? "key \"" : "missing key \"") + key +
                     (json.contains(key) ? "\" is not a number" : "\""));
  }
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw InputError(std::string("key \"") + key + "\" is not finite");
  return d;
}

}  // namespace

BatchCase ParseBatchCase(const nlohmann::json& json, const std::string& base_dir) {
  if (!json.is_object()) throw InputError("a case must be a JSON object");
  BatchCase c;
  if (json.contains("id")) c.id = json["id"];
  c.model_path = Resolve(Required<std::string>(json, "model"), base_dir);
  c.camera_path = Resolve(Required<std::string>(json, "camera"), base_dir);
  if (json.contains("camera_name")) c.camera_name = Required<std::string>(json, "camera_name");
  if (!json.contains("lines") || !json["lines"].is_array()) {
    throw InputError("key \"lines\" must be an array of [u1, v1, u2, v2]");
  }
  for (size_t i = 0; i < json["lines"].size(); ++i) {
    const nlohmann::json& l = json["lines"][i];
    if (!l.is_array() || l.size() != 4) {
      throw InputError("lines[" + std::to_string(i) + "] must be [u1, v1, u2, v2]");
    }
    double v[4];
    for (int k = 0; k < 4; ++k) {
      if (!l[k].is_number()) {
        throw InputError("lines[" + std::to_string(i) + "] holds a value that is not a number");
      }
      v[k] = l[k].get<double>();
    }
    c.problem.lines.push_back({{v[0], v[1]}, {v[2], v[3]}});
  }
  c.problem.height = FiniteNumber(json, "height");
  if (c.problem.height <= 0.0) {
    throw InputError("key \"height\" is not a camera height (metres above the floor, > 0)");
  }
  if (json.contains("storey")) {
    if (!json["storey"].is_number_integer() || json["storey"].get<int>() < 0) {
      throw InputError("key \"storey\" must be an integer >= 0");
    }
    c.storey = json["storey"].get<int>();
  }
  if (json.contains("floor_z")) c.floor_z = FiniteNumber(json, "floor_z");
  c.problem.tilt = DegToRad(FiniteNumber(json, "tilt"));
  if (!json.contains("prior") || json["prior"].is_null()) {
    c.global = true;  // checked by the global localizer
    return c;
  }
  if (!json["prior"].is_array() || json["prior"].size() != 3 || !json["prior"][0].is_number() ||
      !json["prior"][1].is_number() || !json["prior"][2].is_number()) {
    throw InputError("key \"prior\" must be [x, y, heading_deg]");
  }
  c.problem.prior = {json["prior"][0].get<double>(), json["prior"][1].get<double>(),
                     DegToRad(json["prior"][2].get<double>())};
  c.problem.delta_t = FiniteNumber(json, "delta_t");
  c.problem.delta_phi = DegToRad(FiniteNumber(json, "delta_phi"));
  CheckProblem(c.problem);
  return c;
}

}  // namespace linetrack::app
