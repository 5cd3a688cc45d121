// What `replay` and `live` write of each pose's integrity (docs/integrity.md): the flags
// (--alert-limit, --camera-sigma, --all-poses), the frames.csv columns (status, sigmas, protection
// levels), covariance.jsonl (one line per frame with the 6 x 6 world-twist covariance), and the
// summary's sigma quantiles and, with ground truth, integrity failures and NEES calibration.
#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tracking/integrity/integrity_monitor.h"
#include "tracking/tracker/odometry_coast.h"

namespace linetrack::app {

struct IntegrityFlags {
  std::string alert_limit = "0.10,2";  // metres, degrees
  std::string camera_sigma;            // FOCAL_RELATIVE,PRINCIPAL_POINT_PX (default: the solver's)
  double model_sigma_m = EdgeNoiseOptions().model_sigma_m;
  double casing_sigma_m = EdgeNoiseOptions().casing_sigma_m;
  double edge_fault_prior = IntegrityOptions().edge_fault_probability;
  // Risk of a wrong fault exclusion that the levels after an exclusion may leave uncovered.
  double exclusion_risk = IntegrityOptions().exclusion_risk;
  // What the solve does with the intrinsics and the mount's height, tilt and roll: "estimate"
  // or "consider" for both, or "INTRINSICS,MOUNT" (e.g. "consider,estimate"); empty: the default.
  std::string held_parameters;
  bool all_poses = false;  // poses.txt: every pose, not only those tracking

  // The options they set on `base`. Throws InputError naming the flag when malformed.
  IntegrityOptions Options(const IntegrityOptions& base = IntegrityOptions()) const;
};

// Adds --alert-limit, --camera-sigma, --model-sigma, --casing-sigma, --edge-fault-prior,
// --exclusion-risk and --held-parameters to `cmd`; AddAllPosesFlag --all-poses.
void AddIntegrityFlags(CLI::App* cmd, IntegrityFlags* flags);
void AddAllPosesFlag(CLI::App* cmd, IntegrityFlags* flags);

// Coasting on the odometry (replay, live): the odometry's stated error bound and the limits.
struct CoastFlags {
  std::string odometry_bound = "0.15,3,0.15";  // share of distance, degrees per metre, turn share
  std::string coast_limit = "2,50";            // metres, frames since the last image fix

  // The options they set. Throws InputError naming the flag when malformed.
  CoastOptions Options() const;
};

// Adds --odometry-bound and --coast-limit to `cmd`.
void AddCoastFlags(CLI::App* cmd, CoastFlags* flags);

// The pose's integrity for JSON: status, reason, sigmas, protection levels and the 6 x 6
// covariance of the world twist (null without one).
nlohmann::ordered_json UncertaintyJson(const PoseUncertainty& u);

// The frames.csv columns after `status`: sigma_x_m, sigma_y_m, sigma_heading_deg,
// protection_level_m, protection_level_deg (empty fields without a covariance).
extern const char* const kIntegrityCsvColumns;
std::string IntegrityCsvFields(const PoseUncertainty& u);

// One frame's integrity against the truth (cam_from_world of both): the NEES of (x, y, heading)
// with the covariance's (0, 1, 5) block, and whether a tracking pose is beyond its protection
// levels (an integrity failure): horizontal position and heading for a robot, the camera centre
// and the rotation angle for a free camera.
struct IntegrityCheck {
  double nees = 0.0;
  double position_error_m = 0.0;  // horizontal
  double heading_error_rad = 0.0;
  bool failure = false;
};
std::optional<IntegrityCheck> CheckAgainstTruth(const PoseUncertainty& u,
                                                const Eigen::Isometry3d& estimate,
                                                const Eigen::Isometry3d& truth, bool robot);

// covariance.jsonl: {"frame", "t", "status", "covariance": 6 x 6 rows or null} per line, the
// covariance of the world twist (dC metres, omega radians; world axes). Flushed line by line.
class CovarianceLog {
 public:
  // Creates DIR/covariance.jsonl; throws InputError when it cannot.
  explicit CovarianceLog(const std::string& dir);
  void Add(long frame, double t, const PoseUncertainty& u);

 private:
  std::ofstream out_;
};

// Collects the frames' uncertainties for summary.json.
class IntegrityTally {
 public:
  void Add(const PoseUncertainty& u, const std::optional<IntegrityCheck>& check);
  // {"status_counts", "sigma_x_m", "sigma_y_m", "sigma_heading_deg", "protection_level_m",
  //  "protection_level_deg" (p50, p90, p99, max of the frames with a covariance), and with
  //  ground truth "ground_truth": integrity failures, NEES calibration table}.
  nlohmann::ordered_json Summary(const IntegrityOptions& options) const;
  int integrity_failures() const { return failures_; }

 private:
  int counts_[3] = {0, 0, 0};
  std::vector<double> sigma_x_, sigma_y_, sigma_heading_deg_, protection_m_, protection_deg_;
  std::vector<double> nees_, sigma_for_error_, errors_;
  int failures_ = 0, checked_tracking_ = 0;
};

}  // namespace linetrack::app
