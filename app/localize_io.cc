#include "app/localize_io.h"

#include <spdlog/spdlog.h>

#include <cmath>

#include "app/cli_common.h"
#include "app/model_loading.h"
#include "models/errors.h"

namespace linetrack::app {

double CameraZ(const WireframeModel& model, double height, int storey, double floor_z) {
  if (std::isfinite(floor_z)) return floor_z + height;
  const int s = std::max(storey, 0);
  if (s >= static_cast<int>(model.storeys().size())) {
    throw InputError("storey " + std::to_string(s) + ": " + model.path() + " has " +
                     std::to_string(model.storeys().size()) + " storeys (0 is the lowest)");
  }
  return model.storeys()[s].floor_z + height;
}

nlohmann::ordered_json ResultToJson(const nlohmann::json& id, const LocalizationResult& result,
                                    double time_ms, const WireframeModel* model) {
  nlohmann::ordered_json out;
  out["id"] = id;
  out["found"] = result.found;
  if (result.found) {
    out["pose"] = {{"x", result.pose.x},
                   {"y", result.pose.y},
                   {"heading_deg", RadToDeg(WrapAngle(result.pose.heading))}};
    nlohmann::ordered_json cmo = nlohmann::ordered_json::array();
    const Eigen::Matrix4d m = result.cam_from_world.matrix();
    for (int r = 0; r < 4; ++r) {
      cmo.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
    }
    out["cMo"] = cmo;
    out["score"] = result.score_px;
    out["support"] = result.support;
  } else {
    out["pose"] = nullptr;
    out["cMo"] = nullptr;
    out["score"] = nullptr;
    out["reason"] = result.reason;
  }
  nlohmann::ordered_json matches = nlohmann::ordered_json::array();
  for (const auto& [edge, line] : result.matches)
    matches.push_back({edge, line});
  out["matches"] = matches;
  if (model) {
    nlohmann::ordered_json names = nlohmann::ordered_json::array();
    for (const auto& match : result.matches)
      names.push_back(model->edges().at(static_cast<size_t>(match.first)).name);
    out["edge_names"] = names;
  }
  out["hypotheses"] = result.hypotheses;
  out["candidate_edges"] = result.candidate_edges;
  out["tree_nodes"] = result.tree_nodes;
  out["time_ms"] = time_ms;
  return out;
}

nlohmann::ordered_json GlobalResultToJson(const nlohmann::json& id, const GlobalResult& result,
                                          double time_ms, const WireframeModel* model) {
  LocalizationResult shown = result.best;
  if (!result.found) {
    shown = LocalizationResult();
    shown.reason = result.reason;
    for (const PeakVerification& v : result.verifications)
      shown.hypotheses += v.result.hypotheses;
  }
  nlohmann::ordered_json out = ResultToJson(id, shown, time_ms, model);
  out["global"] = true;
  out["ambiguous"] = result.ambiguous;
  if (!result.found) out["answer"] = result.ambiguous ? "ambiguous" : "none";
  nlohmann::ordered_json rivals = nlohmann::ordered_json::array();
  for (const Pose3Dof& p : result.rivals) {
    rivals.push_back({{"x", p.x}, {"y", p.y}, {"heading_deg", RadToDeg(WrapAngle(p.heading))}});
  }
  out["rivals"] = rivals;
  nlohmann::ordered_json headings = nlohmann::ordered_json::array();
  for (const HeadingSearch& s : result.searches)
    headings.push_back(RadToDeg(WrapAngle(s.heading)));
  out["headings_deg"] = headings;
  out["searches"] = result.searches.size();
  out["verified_peaks"] = result.verifications.size();
  return out;
}

const LoadedModel& LocalizerCache::Model(const std::string& model_path) {
  auto it = models_.find(model_path);
  if (it != models_.end()) return it->second;
  LoadedModel loaded;
  loaded.model = std::make_unique<WireframeModel>(LoadModel(model_path));
  loaded.directions = DominantDirections(*loaded.model);
  try {
    loaded.area = std::make_unique<NavigableArea>(NavigableArea::FromModel(*loaded.model));
    loaded.regions = std::make_unique<ViewInvariantRegions>(
        ViewInvariantRegions::Build(*loaded.model, *loaded.area));
  } catch (const InputError& e) {
    loaded.area_problem = e.what();
    spdlog::warn("{}: no navigable area ({}); every edge is a candidate", model_path, e.what());
  }
  return models_.emplace(model_path, std::move(loaded)).first->second;
}

const Localizer& LocalizerCache::Get(const std::string& model_path, const std::string& camera_path,
                                     const std::string& camera_name) {
  const std::string key = model_path + "\n" + camera_path + "\n" + camera_name;
  auto it = localizers_.find(key);
  if (it != localizers_.end()) return *it->second;
  const LoadedModel& model = Model(model_path);
  const std::string camera_key = camera_path + "\n" + camera_name;
  auto cam = cameras_.find(camera_key);
  if (cam == cameras_.end()) {
    cam = cameras_.emplace(camera_key, LoadCamera(camera_path, camera_name)).first;
  }
  if (cam->second.width <= 0) {
    throw InputError(Located(camera_path, 0, "the camera file gives no image size"));
  }
  auto localizer = std::make_unique<Localizer>(*model.model, model.regions.get(), model.area.get(),
                                               cam->second, options_);
  return *localizers_.emplace(key, std::move(localizer)).first->second;
}

const GlobalLocalizer& LocalizerCache::GetGlobal(const std::string& model_path,
                                                 const std::string& camera_path,
                                                 const std::string& camera_name) {
  const std::string key = model_path + "\n" + camera_path + "\n" + camera_name;
  auto it = globals_.find(key);
  if (it != globals_.end()) return *it->second;
  const Localizer& localizer = Get(model_path, camera_path, camera_name);
  const LoadedModel& model = Model(model_path);
  if (!model.area) {
    throw InputError(model_path + ": the global mode needs a navigable area (" +
                     model.area_problem + ")");
  }
  if (model.directions.angles.empty()) {
    throw InputError(model_path + ": the global mode needs horizontal model edges");
  }
  auto global =
      std::make_unique<GlobalLocalizer>(localizer, model.directions, GlobalOptionsFor(options_));
  return *globals_.emplace(key, std::move(global)).first->second;
}

}  // namespace linetrack::app
