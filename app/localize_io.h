// Files of `linetrack localize`: the batch cases (JSON lines) and the result JSON, plus a cache
// that loads each model and camera once (the line CSV: app/lines_csv.h).
#pragma once

#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "matching/global/global_localizer.h"
#include "matching/heading/model_directions.h"
#include "matching/localizer.h"
#include "models/navigable_area.h"
#include "models/view_invariant_regions.h"

namespace linetrack::app {

// One case of a batch file (see docs/matching.md for the format).
struct BatchCase {
  nlohmann::json id;       // the case's "id" as given (a string, a number...); null without one
  std::string model_path;  // resolved against the batch file's folder
  std::string camera_path;
  std::string camera_name;  // optional "camera_name" key
  // Which floor "height" is measured from: the optional "storey" key (an index into the model's
  // storeys; -1: not given, storey 0) or "floor_z" (world z, metres; NaN: not given).
  int storey = -1;
  double floor_z = std::numeric_limits<double>::quiet_NaN();
  LocalizationProblem problem;  // problem.height: above that floor until CameraZ() is applied;
                                // its prior, delta_t and delta_phi unset when global
  bool global = false;          // no "prior" key, or "prior": null
};

// Parses one JSON line of a batch file; relative paths are resolved against `base_dir`. A case
// without "prior" (or with "prior": null) is global: delta_t and delta_phi are then ignored.
// Throws InputError naming the missing or malformed key.
BatchCase ParseBatchCase(const nlohmann::json& json, const std::string& base_dir);

// World z of a camera `height` metres above the floor of `storey` (-1: storey 0) of `model`, or
// above `floor_z` when finite. Throws InputError when the storey does not exist.
double CameraZ(const WireframeModel& model, double height, int storey, double floor_z);

// The result of one case as a JSON object: id (as given), found, pose, cMo, matches ([edge,
// line] pairs), score, hypotheses, time_ms (and diagnostics: candidate_edges, tree_nodes,
// reason); with `model`, also edge_names: the name of each match's edge ("" when unnamed).
nlohmann::ordered_json ResultToJson(const nlohmann::json& id, const LocalizationResult& result,
                                    double time_ms, const WireframeModel* model = nullptr);

// The result of a global case: ResultToJson of the accepted search (or of the failure) with
// "global": true, "ambiguous", "answer" ("ambiguous" or "none") when no pose, the rival poses
// ({x, y, heading_deg} each) when ambiguous, the heading candidates (degrees) and the searches.
nlohmann::ordered_json GlobalResultToJson(const nlohmann::json& id, const GlobalResult& result,
                                          double time_ms, const WireframeModel* model = nullptr);

// A model with what localisation needs beside it: navigable area (when derivable) and
// view-invariant regions.
struct LoadedModel {
  std::unique_ptr<WireframeModel> model;
  std::unique_ptr<NavigableArea> area;            // null when it cannot be derived
  std::unique_ptr<ViewInvariantRegions> regions;  // null without an area
  ModelDirections directions;                     // dominant horizontal directions
  std::string area_problem;                       // why there is no area
};

// Loads models, cameras and localizers once per distinct path (and camera name).
class LocalizerCache {
 public:
  explicit LocalizerCache(LocalizerOptions options) : options_(std::move(options)) {}

  // Throws InputError when the model or camera cannot be read.
  const Localizer& Get(const std::string& model_path, const std::string& camera_path,
                       const std::string& camera_name);
  const LoadedModel& Model(const std::string& model_path);
  // The global localizer of the model and camera. Throws InputError when the model has no
  // navigable area or no horizontal direction.
  const GlobalLocalizer& GetGlobal(const std::string& model_path, const std::string& camera_path,
                                   const std::string& camera_name);

 private:
  LocalizerOptions options_;
  std::map<std::string, LoadedModel> models_;
  std::map<std::string, CameraIntrinsics> cameras_;
  std::map<std::string, std::unique_ptr<Localizer>> localizers_;
  std::map<std::string, std::unique_ptr<GlobalLocalizer>> globals_;
};

}  // namespace linetrack::app
