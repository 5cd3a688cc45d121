// The files of `linetrack replay`: poses.txt (TUM) and frames.csv written and flushed frame by
// frame, the overlay video (or PNG frames), summary.json and the error plot.
#pragma once

#include <Eigen/Geometry>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/integrity_output.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack::app {

// What the summary and the plot keep of each frame.
struct ReplayFrameRecord {
  long frame = 0;  // the frame's number in its file or sequence
  double t = 0.0;  // seconds
  TrackStatus status = TrackStatus::kInitialising;
  bool has_pose = false;
  double projection_error_deg = 0.0;
  int edges_good = 0;
  double step_ms = 0.0;    // the tracking step (undistortion, tracking, health, re-localisation)
  double decode_ms = 0.0;  // reading the frame
  std::optional<double> translation_error_m;  // camera centre vs ground truth
  std::optional<double> rotation_error_deg;
};

// poses.txt (the poses `tracking`, or all with `all_poses`), frames.csv (status: tracking,
// degraded, lost; state: the tracker's) and covariance.jsonl, each line flushed as soon as its
// frame is done, so that an interrupted replay leaves valid files up to the last frame.
class ReplayLog {
 public:
  // Creates the files in `dir` (which must exist); throws InputError when it cannot.
  ReplayLog(const std::string& dir, bool with_ground_truth, bool all_poses);

  void Add(const ReplayFrameRecord& record, const FrameReport& report);

 private:
  std::ofstream poses_;
  std::ofstream frames_;
  CovarianceLog covariance_;
  bool with_ground_truth_;
  bool all_poses_;
};

// The overlay video: H.264 in .mp4 ('avc1'), else MPEG-4 part 2 ('mp4v'), else Motion-JPEG in
// .avi; or one PNG a frame in DIR/overlay/. Frames must all have the first one's size.
class OverlayWriter {
 public:
  // Throws InputError when nothing can be written.
  OverlayWriter(const std::string& dir, bool png_frames, double fps, cv::Size size);

  void Add(const cv::Mat& bgr, long frame);
  void Close();  // finalises the video (also done by the destructor)
  ~OverlayWriter();

  const std::string& path() const { return path_; }
  const std::string& codec() const { return codec_; }

 private:
  std::string path_;
  std::string codec_;
  cv::VideoWriter video_;
  bool png_ = false;
};

// The overlay of one frame: the undistorted image, the visible model edges at the reported pose
// (green while tracking, orange when degraded), a status line (the integrity status and the
// tracker's state), the pose (x, y, z, heading, tilt) with its sigmas and protection levels, or
// why there is none.
cv::Mat DrawOverlay(const vpImage<unsigned char>& undistorted,
                    const std::vector<Segment2>& model_edges, const FrameReport& report, long frame,
                    double t);

// Translation (cm) and rotation (degrees) errors against the frame number, with the frames
// without a pose marked; nullopt when no frame has an error.
std::optional<cv::Mat> DrawErrorPlot(const std::vector<ReplayFrameRecord>& records);

// Facts about the run the summary repeats.
struct ReplayRunInfo {
  std::string input, model, camera, settings;
  bool complete = false;     // the input was read to its end
  std::string interruption;  // why the run stopped early (empty when complete)
  double wall_s = 0.0;       // from the first grab to the last frame written
  double overlay_s = 0.0;    // drawing and encoding the overlay (excluded from throughput)
  std::string overlay_path, overlay_codec, error_plot;
  int losses = 0, recoveries = 0;
  nlohmann::ordered_json integrity;  // IntegrityTally::Summary
};

// summary.json: frames, tracked share, losses and recoveries, status counts, timing percentiles,
// throughput, the integrity (info.integrity); with ground truth the ATE (RMSE of the camera
// centre errors) and error statistics.
nlohmann::ordered_json ReplaySummary(const std::vector<ReplayFrameRecord>& records,
                                     const ReplayRunInfo& info);

}  // namespace linetrack::app
