// The figures of `linetrack bench drive`: a replay's frames (its frames.csv) judged against the
// rendered drive's truth (frame_truth.csv): availability over the observable frames, wrong poses,
// ATE, recovery after blackouts, replay speed; and the markdown tables that show them.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "models/render/frame_truth.h"

namespace linetrack::app {

// One row of replay's frames.csv, read by its column names.
struct ReplayedFrame {
  long frame = 0;
  double t = 0.0;
  std::string status;  // the integrity status: tracking, degraded, lost
  std::string source;  // where the pose came from ("odometry": coasted); empty without the column
  double step_ms = 0.0;
  bool has_pose = false;                      // an error was measured: the frame has a pose
  std::optional<double> translation_error_m;  // camera centre against the ground truth
  std::optional<double> rotation_error_deg;
  std::string note;
};

// Parses frames.csv text (header with at least frame, time, status, time_ms,
// translation_error_m, rotation_error_deg; `note` last). Throws InputError naming `source`:line.
std::vector<ReplayedFrame> ParseReplayFrames(const std::string& text, const std::string& source);

struct DriveMetricsOptions {
  double near_m = 0.10, near_deg = 2.0;  // a pose beyond either is wrong
  double far_m = 0.50, far_deg = 5.0;    // a pose beyond either is far off
  int worst = 8;                         // frames listed in the worst-frames table

  bool Check(std::string* why) const;
};

// The frames from the end of one blackout until a good pose again.
struct BlackoutRecovery {
  long first = 0, last = 0;    // the covered frames
  long first_observable = -1;  // the first observable frame after them (-1: none)
  // From there, the first frame with an image pose (not coasted) within near bounds.
  long recovered = -1;
  int frames_to_recover = -1;  // recovered - first_observable; -1 when never
};

// The frames from a kidnap's put-down until a `tracking` pose within the near bounds.
struct KidnapRecovery {
  long frame = 0;              // the put-down
  long first_observable = -1;  // the first observable frame from there (-1: none)
  long recovered = -1;         // from there, the first `tracking` pose within near bounds
  int frames_to_recover = -1;  // recovered - first_observable; -1 when never
  int wrong_tracking = 0;      // `tracking` poses beyond the near bounds from the put-down on,
                               // until recovered (or the next kidnap)
};

struct DriveMetrics {
  int frames = 0;
  int observable = 0;
  int observable_with_pose = 0;
  int observable_tracking = 0;          // observable frames with a pose whose status is `tracking`
  int observable_tracking_coasted = 0;  // ... of which the odometry carried (source odometry)
  int poses = 0;
  int poses_unobservable = 0;  // poses on frames that are not observable
  int beyond_near = 0, beyond_far = 0;
  int tracking_beyond_near = 0;  // poses `tracking` beyond the near bounds
  double ate_m = 0.0;            // RMSE of the camera-centre errors of the frames with a pose
  double worst_m = 0.0, worst_deg = 0.0;
  long worst_m_frame = -1, worst_deg_frame = -1;
  std::vector<BlackoutRecovery> recoveries;
  std::vector<KidnapRecovery> kidnaps;  // AddKidnapRecoveries; none: the row says so
  double tracking_fps = 0.0;            // tracking frames over their summed step time
  double overall_fps = 0.0;             // the replay's throughput (decoding and every step)
  std::vector<size_t> worst_frames;     // indexes into the replayed frames, worst first
  // From replay's summary "integrity" (AddIntegrityFigures); n/a without it.
  std::optional<int> integrity_failures;
  std::optional<double> nees_within_99;
  std::array<double, 4> nees_shares = {};  // within chi2(3) 50, 90, 99, 99.9 %
  double mean_nees = 0.0;
  double median_sigma_m = 0.0, median_error_m = 0.0;
  double sigma_x_p50_m = 0.0, sigma_x_p90_m = 0.0, sigma_heading_p50_deg = 0.0;
  double protection_p50_m = 0.0, protection_p90_m = 0.0;  // over the frames with a covariance

  double Availability() const;          // observable frames with a pose / observable frames
  double TrackingAvailability() const;  // ... with a `tracking` pose
};

// Judges `replayed` against `truth` (matched by frame number; frames missing from either are
// skipped). `overall_fps` is the replay summary's throughput.
DriveMetrics ComputeDriveMetrics(const std::vector<FrameTruth>& truth,
                                 const std::vector<ReplayedFrame>& replayed, double overall_fps,
                                 const DriveMetricsOptions& options = {});

// The recovery after each kidnap (`kidnap_frames`: the put-down frames of sequence.json's
// "kidnaps", increasing) into `metrics`.
void AddKidnapRecoveries(const std::vector<FrameTruth>& truth,
                         const std::vector<ReplayedFrame>& replayed,
                         const std::vector<long>& kidnap_frames, const DriveMetricsOptions& options,
                         DriveMetrics* metrics);

// Reads replay's summary.json "integrity" (with ground truth) into `metrics`: integrity failures,
// the NEES calibration against chi2(3), the sigma quantiles. Leaves them n/a when absent.
void AddIntegrityFigures(const nlohmann::json& integrity, DriveMetrics* metrics);

// A named drive's figures for the tables.
struct DriveReport {
  std::string name;
  DriveMetrics metrics;
  double drift_percent = 0.0;  // the odometry's largest drift over 10 m windows
};

// The markdown table: one row per figure, one column per drive.
std::string FormatDriveTable(const std::vector<DriveReport>& reports,
                             const DriveMetricsOptions& options = {});

// The markdown list of one drive's worst frames (by position error) with their truth.
std::string FormatWorstFrames(const DriveMetrics& metrics, const std::vector<FrameTruth>& truth,
                              const std::vector<ReplayedFrame>& replayed);

}  // namespace linetrack::app
