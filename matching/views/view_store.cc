#include "matching/views/view_store.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "models/errors.h"

namespace linetrack {
namespace {

using nlohmann::json;

json CameraJson(const CameraIntrinsics& c) {
  return {{"width", c.width}, {"height", c.height}, {"px", c.px},
          {"py", c.py},       {"u0", c.u0},         {"v0", c.v0}};
}

// The value of `key` in `object` as T; throws InputError naming the file, line and key.
template <typename T>
T Field(const json& object, const char* key, const std::string& file, int line) {
  if (!object.is_object() || !object.contains(key)) {
    throw InputError(Located(file, line, std::string("missing \"") + key + "\""));
  }
  try {
    return object.at(key).get<T>();
  } catch (const json::exception&) {
    throw InputError(Located(file, line, std::string("\"") + key + "\" has the wrong type"));
  }
}

double Finite(double v, const std::string& file, int line, const char* what) {
  if (!std::isfinite(v))
    throw InputError(Located(file, line, std::string(what) + " is not finite"));
  return v;
}

KeyView ParseKeyView(const json& j, const std::string& file, int line) {
  KeyView view;
  view.id = Field<int>(j, "id", file, line);
  const json pose = Field<json>(j, "pose", file, line);
  view.pose.x = Finite(Field<double>(pose, "x", file, line), file, line, "pose x");
  view.pose.y = Finite(Field<double>(pose, "y", file, line), file, line, "pose y");
  view.pose.heading =
      DegToRad(Finite(Field<double>(pose, "heading_deg", file, line), file, line, "heading"));
  view.pose.height = Finite(Field<double>(pose, "height", file, line), file, line, "height");
  view.pose.tilt =
      DegToRad(Finite(Field<double>(pose, "tilt_deg", file, line), file, line, "tilt"));
  for (const json& s : Field<json>(j, "segments", file, line)) {
    if (!s.is_array() || s.size() != 5) {
      throw InputError(Located(file, line, "a segment is not [u1, v1, u2, v2, line_id]"));
    }
    ViewSegment seg;
    try {
      seg.image = {{s[0].get<double>(), s[1].get<double>()},
                   {s[2].get<double>(), s[3].get<double>()}};
      seg.line_id = s[4].get<int>();
    } catch (const json::exception&) {
      throw InputError(Located(file, line, "a segment has a non-numeric field"));
    }
    if (!seg.image.a.allFinite() || !seg.image.b.allFinite() || seg.image.Length() == 0.0) {
      throw InputError(Located(file, line, "a segment is not finite or has zero length"));
    }
    view.segments.push_back(seg);
  }
  for (const json& s : Field<json>(j, "junctions", file, line)) {
    if (!s.is_array() || s.size() != 4 || !s[3].is_array()) {
      throw InputError(Located(file, line, "a junction is not [point_id, u, v, [line_id, ...]]"));
    }
    ViewJunction junction;
    try {
      junction = {
          s[0].get<int>(), {s[1].get<double>(), s[2].get<double>()}, s[3].get<std::vector<int>>()};
    } catch (const json::exception&) {
      throw InputError(Located(file, line, "a junction has a non-numeric field"));
    }
    if (!junction.pixel.allFinite() || junction.lines.size() < 2) {
      throw InputError(Located(file, line, "a junction is not finite or has fewer than 2 lines"));
    }
    view.junctions.push_back(junction);
  }
  return view;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::string ViewIndexJson(const ViewDatabase& db) {
  const json index = {{"format", "linetrack-views"},
                      {"version", 1},
                      {"camera", CameraJson(db.camera)},
                      {"model", db.model_path},
                      {"tokens",
                       {{"neighbours", db.token_options.neighbours},
                        {"min_length_px", db.token_options.min_length_px},
                        {"sigma", db.token_options.sigma},
                        {"outlier_probability", db.token_options.outlier_probability}}},
                      {"views", kViewLinesFile},
                      {"count", db.views.size()}};
  return index.dump(2) + "\n";
}

std::string KeyViewJsonLine(const KeyView& view) {
  json segments = json::array(), junctions = json::array();
  for (const ViewSegment& s : view.segments) {
    segments.push_back({s.image.a.x(), s.image.a.y(), s.image.b.x(), s.image.b.y(), s.line_id});
  }
  for (const ViewJunction& j : view.junctions) {
    junctions.push_back({j.point_id, j.pixel.x(), j.pixel.y(), j.lines});
  }
  const json line = {{"id", view.id},
                     {"pose",
                      {{"x", view.pose.x},
                       {"y", view.pose.y},
                       {"heading_deg", RadToDeg(view.pose.heading)},
                       {"height", view.pose.height},
                       {"tilt_deg", RadToDeg(view.pose.tilt)}}},
                     {"segments", segments},
                     {"junctions", junctions}};
  return line.dump() + "\n";
}

ViewDatabase ParseViewDatabase(const std::string& index_text, const std::string& views_text,
                               const std::string& dir) {
  const std::string index_file = dir + "/" + kViewIndexFile;
  const std::string views_file = dir + "/" + kViewLinesFile;
  json index;
  try {
    index = json::parse(index_text);
  } catch (const json::exception&) {
    throw InputError(index_file + ": not valid JSON");
  }
  if (Field<std::string>(index, "format", index_file, 0) != "linetrack-views") {
    throw InputError(index_file + ": \"format\" is not \"linetrack-views\"");
  }
  ViewDatabase db;
  const json camera = Field<json>(index, "camera", index_file, 0);
  db.camera.width = Field<int>(camera, "width", index_file, 0);
  db.camera.height = Field<int>(camera, "height", index_file, 0);
  db.camera.px = Field<double>(camera, "px", index_file, 0);
  db.camera.py = Field<double>(camera, "py", index_file, 0);
  db.camera.u0 = Field<double>(camera, "u0", index_file, 0);
  db.camera.v0 = Field<double>(camera, "v0", index_file, 0);
  std::string why;
  if (!db.camera.Check(&why)) throw InputError(index_file + ": camera: " + why);
  db.model_path = Field<std::string>(index, "model", index_file, 0);
  const json tokens = Field<json>(index, "tokens", index_file, 0);
  db.token_options.neighbours = Field<int>(tokens, "neighbours", index_file, 0);
  db.token_options.min_length_px = Field<double>(tokens, "min_length_px", index_file, 0);
  db.token_options.sigma = Field<double>(tokens, "sigma", index_file, 0);
  db.token_options.outlier_probability =
      Field<double>(tokens, "outlier_probability", index_file, 0);
  if (!db.token_options.Check(&why)) throw InputError(index_file + ": " + why);
  std::istringstream lines(views_text);
  std::string text;
  for (int line = 1; std::getline(lines, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    json j;
    try {
      j = json::parse(text);
    } catch (const json::exception&) {
      throw InputError(Located(views_file, line, "not valid JSON"));
    }
    db.views.push_back(ParseKeyView(j, views_file, line));
  }
  if (db.views.empty()) throw InputError(views_file + ": no key views");
  ComputeViewTokens(&db);
  return db;
}

ViewDatabase LoadViewDatabase(const std::string& dir) {
  const std::string index = ReadText(dir + "/" + kViewIndexFile);
  return ParseViewDatabase(index, ReadText(dir + "/" + kViewLinesFile), dir);
}

}  // namespace linetrack
