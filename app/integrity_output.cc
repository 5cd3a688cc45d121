#include "app/integrity_output.h"

#include <cmath>
#include <cstdio>

#include "app/cli_common.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/statistics.h"
#include "tracking/integrity/consistency.h"
#include "tracking/integrity/edge_residual.h"

namespace linetrack::app {

namespace {

std::string Fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

nlohmann::ordered_json Quantiles(const std::vector<double>& values) {
  if (values.empty()) return nullptr;
  return {{"p50", QuantileNearestRank(values, 0.5)},
          {"p90", QuantileNearestRank(values, 0.9)},
          {"p99", QuantileNearestRank(values, 0.99)},
          {"max", QuantileNearestRank(values, 1.0)}};
}

// The covariance of (x, y, heading): rows and columns 0, 1, 5 of the world twist's.
Eigen::Matrix3d PlanarBlock(const Eigen::Matrix<double, 6, 6>& c) {
  const int index[3] = {0, 1, 5};
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      out(i, j) = c(index[i], index[j]);
  }
  return out;
}

// The 6 x 6 rows, or null without a covariance.
nlohmann::ordered_json CovarianceJson(const PoseUncertainty& u) {
  if (!u.has_covariance()) return nullptr;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int i = 0; i < 6; ++i) {
    std::vector<double> row(6);
    for (int j = 0; j < 6; ++j)
      row[j] = u.world_covariance(i, j);
    rows.push_back(row);
  }
  return rows;
}

// "estimate" or "consider" (--held-parameters).
ConsideredUncertainty::Handling ParseHandling(const std::string& word) {
  if (word == "estimate") return ConsideredUncertainty::Handling::kEstimate;
  if (word == "consider") return ConsideredUncertainty::Handling::kConsider;
  throw InputError("--held-parameters: '" + word +
                   "' is neither 'estimate' nor 'consider' (give one, or INTRINSICS,MOUNT)");
}

}  // namespace

IntegrityOptions IntegrityFlags::Options(const IntegrityOptions& base) const {
  IntegrityOptions options = base;
  const std::vector<double> alert =
      ParseNumberList(alert_limit, 2, "--alert-limit", "METRES,DEGREES");
  CheckRange(alert[0], 1e-4, 100.0, "--alert-limit (metres)");
  CheckRange(alert[1], 1e-3, 180.0, "--alert-limit (degrees)");
  options.alert_position_m = alert[0];
  options.alert_rotation_rad = DegToRad(alert[1]);
  if (!camera_sigma.empty()) {
    const std::vector<double> sigma =
        ParseNumberList(camera_sigma, 2, "--camera-sigma", "FOCAL_RELATIVE,PRINCIPAL_POINT_PX");
    CheckRange(sigma[0], 0.0, 0.5, "--camera-sigma (relative focal sigma)");
    CheckRange(sigma[1], 0.0, 1000.0, "--camera-sigma (principal point sigma, pixels)");
    options.solver.considered.focal_relative = sigma[0];
    options.solver.considered.principal_point_px = sigma[1];
  }
  CheckRange(model_sigma_m, 0.0, 1.0, "--model-sigma");
  options.solver.noise.model_sigma_m = model_sigma_m;
  CheckRange(casing_sigma_m, 0.0, 1.0, "--casing-sigma");
  options.solver.noise.casing_sigma_m = casing_sigma_m;
  if (!held_parameters.empty()) {
    const size_t comma = held_parameters.find(',');
    ConsideredUncertainty& c = options.solver.considered;
    c.intrinsics = ParseHandling(held_parameters.substr(0, comma));
    c.mount = comma == std::string::npos ? c.intrinsics
                                         : ParseHandling(held_parameters.substr(comma + 1));
  }
  CheckRange(edge_fault_prior, 0.0, 0.5, "--edge-fault-prior");
  options.edge_fault_probability = edge_fault_prior;
  CheckRange(exclusion_risk, 1e-12, 0.25, "--exclusion-risk");
  options.exclusion_risk = exclusion_risk;
  std::string why;
  if (!options.Check(&why)) throw InputError("--alert-limit/--camera-sigma: " + why);
  return options;
}

void AddIntegrityFlags(CLI::App* cmd, IntegrityFlags* flags) {
  cmd->add_option("--alert-limit", flags->alert_limit,
                  "Alert limit METRES,DEGREES: a pose is 'tracking' only when its protection "
                  "levels are within it, else 'degraded'")
      ->capture_default_str();
  cmd->add_option("--camera-sigma", flags->camera_sigma,
                  "Calibration uncertainty FOCAL_RELATIVE,PRINCIPAL_POINT_PX in the covariance "
                  "(default 0.003,1; 0,0 for exactly known intrinsics)");
  cmd->add_option("--model-sigma", flags->model_sigma_m,
                  "Model error allowance: how far the model's edges may be from the real ones "
                  "(metres, each end)")
      ->capture_default_str();
  cmd->add_option("--casing-sigma", flags->casing_sigma_m,
                  "How far a door or window casing may pull a frame line's edge (metres; the "
                  "model's 3D lines drawn on a face; 0: not at all)")
      ->capture_default_str();
  cmd->add_option("--edge-fault-prior", flags->edge_fault_prior,
                  "Prior probability that one edge's points are wrong beyond the noise (latched "
                  "on an unmodelled line): the protection levels cover such a fault")
      ->capture_default_str();
  cmd->add_option("--exclusion-risk", flags->exclusion_risk,
                  "After the fault test excludes an edge: the probability, beside the integrity "
                  "risk, that a wrong exclusion leaves the error beyond the protection levels "
                  "(docs/integrity.md 2.3); the total risk stays within integrity + 2 x this")
      ->capture_default_str();
  cmd->add_option("--held-parameters", flags->held_parameters,
                  "What the pose solve does with the intrinsics and the camera's height, tilt "
                  "and roll: 'estimate' them with the pose under their stated uncertainty, or "
                  "'consider' them (held at nominal, their uncertainty widening the covariance); "
                  "one word for both or INTRINSICS,MOUNT (default estimate)");
}

CoastOptions CoastFlags::Options() const {
  const std::vector<double> bound = ParseNumberList(odometry_bound, 3, "--odometry-bound",
                                                    "DISTANCE_SHARE,DEGREES_PER_METRE,TURN_SHARE");
  CheckRange(bound[0], 0.0, 0.99, "--odometry-bound (share of the distance driven)");
  CheckRange(bound[1], 0.0, 180.0, "--odometry-bound (degrees per metre)");
  CheckRange(bound[2], 0.0, 0.99, "--odometry-bound (share of the heading turned)");
  const std::vector<double> limit =
      ParseNumberList(coast_limit, 2, "--coast-limit", "METRES,FRAMES");
  CheckRange(limit[0], 0.0, 1000.0, "--coast-limit (metres)");
  CheckRange(limit[1], 0.0, 1e6, "--coast-limit (frames)");
  CoastOptions options;
  options.bound = {bound[0], DegToRad(bound[1]), bound[2]};
  options.max_distance_m = limit[0];
  options.max_frames = static_cast<int>(std::lround(limit[1]));
  options.enabled = options.max_frames > 0;
  return options;
}

void AddCoastFlags(CLI::App* cmd, CoastFlags* flags) {
  cmd->add_option("--odometry-bound", flags->odometry_bound,
                  "The odometry's stated error bound DISTANCE_SHARE,DEGREES_PER_METRE,TURN_SHARE "
                  "per step: the frames without an image pose coast on the odometry, their "
                  "protection levels grown by it (docs/integrity.md)")
      ->capture_default_str();
  cmd->add_option("--coast-limit", flags->coast_limit,
                  "Coasting limit METRES,FRAMES since the last image fix, beyond which the pose "
                  "is lost (0 frames: no coasting)")
      ->capture_default_str();
}

void AddAllPosesFlag(CLI::App* cmd, IntegrityFlags* flags) {
  cmd->add_flag("--all-poses", flags->all_poses,
                "poses.txt: every pose (degraded ones too), not only those 'tracking'");
}

const char* const kIntegrityCsvColumns =
    "sigma_x_m,sigma_y_m,sigma_heading_deg,protection_level_m,protection_level_deg";

std::string IntegrityCsvFields(const PoseUncertainty& u) {
  if (!u.has_covariance()) return ",,,,";
  return Fixed(u.sigma_x_m, 5) + "," + Fixed(u.sigma_y_m, 5) + "," +
         Fixed(RadToDeg(u.sigma_heading_rad), 4) + "," + Fixed(u.protection_position_m, 4) + "," +
         Fixed(RadToDeg(u.protection_rotation_rad), 3);
}

std::optional<IntegrityCheck> CheckAgainstTruth(const PoseUncertainty& u,
                                                const Eigen::Isometry3d& estimate,
                                                const Eigen::Isometry3d& truth, bool robot) {
  if (!u.has_covariance()) return std::nullopt;
  const WorldTwist e = WorldTwistBetween(truth, estimate);
  IntegrityCheck check;
  const Eigen::Vector3d planar(e[0], e[1], e[5]);
  check.nees = Nees(planar, PlanarBlock(u.world_covariance));
  check.position_error_m = e.head<2>().norm();
  check.heading_error_rad = std::abs(e[5]);
  const double position = robot ? check.position_error_m : e.head<3>().norm();
  const double rotation = robot ? check.heading_error_rad : e.tail<3>().norm();
  check.failure = u.status == IntegrityStatus::kTracking &&
                  (position > u.protection_position_m || rotation > u.protection_rotation_rad);
  return check;
}

CovarianceLog::CovarianceLog(const std::string& dir) {
  const std::string path = dir + "/covariance.jsonl";
  out_.open(path, std::ios::trunc);
  if (!out_) throw InputError(path + ": cannot be written");
}

void CovarianceLog::Add(long frame, double t, const PoseUncertainty& u) {
  const nlohmann::ordered_json line = {{"frame", frame},
                                       {"t", t},
                                       {"status", ToString(u.status)},
                                       {"covariance", CovarianceJson(u)}};
  out_ << line.dump() << "\n" << std::flush;
}

nlohmann::ordered_json UncertaintyJson(const PoseUncertainty& u) {
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr; };
  return {{"status", ToString(u.status)},
          {"reason", u.reason},
          {"sigma_x_m", finite(u.sigma_x_m)},
          {"sigma_y_m", finite(u.sigma_y_m)},
          {"sigma_heading_deg", finite(RadToDeg(u.sigma_heading_rad))},
          {"protection_level_m", finite(u.protection_position_m)},
          {"protection_level_deg", finite(RadToDeg(u.protection_rotation_rad))},
          {"covariance", CovarianceJson(u)},
          {"covariance_axes", "world twist dx dy dz (m), wx wy wz (rad)"}};
}

void IntegrityTally::Add(const PoseUncertainty& u, const std::optional<IntegrityCheck>& check) {
  ++counts_[static_cast<int>(u.status)];
  if (u.has_covariance()) {
    sigma_x_.push_back(u.sigma_x_m);
    sigma_y_.push_back(u.sigma_y_m);
    sigma_heading_deg_.push_back(RadToDeg(u.sigma_heading_rad));
    if (std::isfinite(u.protection_position_m)) protection_m_.push_back(u.protection_position_m);
    if (std::isfinite(u.protection_rotation_rad)) {
      protection_deg_.push_back(RadToDeg(u.protection_rotation_rad));
    }
  }
  if (!check) return;
  nees_.push_back(check->nees);
  sigma_for_error_.push_back(std::max(u.sigma_x_m, u.sigma_y_m));
  errors_.push_back(check->position_error_m);
  checked_tracking_ += u.status == IntegrityStatus::kTracking;
  failures_ += check->failure;
}

nlohmann::ordered_json IntegrityTally::Summary(const IntegrityOptions& options) const {
  nlohmann::ordered_json out = {
      {"alert_limit",
       {{"position_m", options.alert_position_m},
        {"rotation_deg", RadToDeg(options.alert_rotation_rad)}}},
      {"status_counts",
       {{"tracking", counts_[static_cast<int>(IntegrityStatus::kTracking)]},
        {"degraded", counts_[static_cast<int>(IntegrityStatus::kDegraded)]},
        {"lost", counts_[static_cast<int>(IntegrityStatus::kLost)]}}},
      {"sigma_x_m", Quantiles(sigma_x_)},
      {"sigma_y_m", Quantiles(sigma_y_)},
      {"sigma_heading_deg", Quantiles(sigma_heading_deg_)},
      {"protection_level_m", Quantiles(protection_m_)},
      {"protection_level_deg", Quantiles(protection_deg_)}};
  if (nees_.empty()) return out;
  CalibrationTally tally(3);
  for (size_t i = 0; i < nees_.size(); ++i)
    tally.Add(nees_[i], sigma_for_error_[i], errors_[i]);
  const CalibrationSummary c = tally.Summary();
  nlohmann::ordered_json regions = nlohmann::ordered_json::array();
  for (size_t i = 0; i < c.shares.size(); ++i) {
    regions.push_back({{"level", CalibrationSummary::kLevels[i]},
                       {"chi2_quantile", c.quantiles[i]},
                       {"share_inside", c.shares[i]}});
  }
  out["ground_truth"] = {{"poses_compared", c.count},
                         {"tracking_compared", checked_tracking_},
                         {"integrity_failures", failures_},
                         {"mean_nees", c.mean_nees},
                         {"nees_dof", c.dof},
                         {"regions", regions},
                         {"median_sigma_m", c.median_sigma},
                         {"median_error_m", c.median_error}};
  return out;
}

}  // namespace linetrack::app
