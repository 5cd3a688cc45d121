#include "tracking/head/head_sweep.h"

#include <algorithm>
#include <cmath>

#include "models/geometry.h"

namespace linetrack {
namespace {

// Grabs one frame (retrying timeouts within the frame budget); false with *failure on an error.
bool GrabOne(FrameSource* source, Frame* frame, int* budget, std::string* failure) {
  while ((*budget)-- > 0) {
    const FrameStatus status = source->Grab(frame);
    if (status == FrameStatus::kOk) return true;
    if (status != FrameStatus::kTimeout) {
      *failure = std::string("the camera: ") + ToString(status) + " " + source->LastError();
      return false;
    }
  }
  *failure = "no frame within the frame budget";
  return false;
}

// Waits, frame by frame, until the head is still; false with *failure otherwise.
bool WaitUntilStill(PanTiltHead* head, FrameSource* source, const Eigen::Vector2d& target,
                    const HeadSweepOptions& options, int* budget, Frame* frame,
                    std::string* failure) {
  HeadState previous;
  int still = 0;
  bool have_previous = false;
  while (still < options.still_readings) {
    if (!GrabOne(source, frame, budget, failure)) return false;
    HeadState state;
    const HeadResult read = head->Read(&state);
    if (!read.ok()) {
      *failure = "head read failed: " + read.message;
      return false;
    }
    const bool same = have_previous && std::abs(state.pan - previous.pan) <= options.still_rad &&
                      std::abs(state.tilt - previous.tilt) <= options.still_rad;
    const bool there = std::abs(state.pan - target.x()) <= options.arrive_rad &&
                       std::abs(state.tilt - target.y()) <= options.arrive_rad;
    still = state.moving || !there ? 0 : (same ? still + 1 : 1);
    previous = state;
    have_previous = true;
  }
  return true;
}

}  // namespace

bool HeadSweepOptions::Check(std::string* why) const {
  if (!(still_rad > 0.0 && still_rad < 0.1) || !(arrive_rad > 0.0 && arrive_rad < 0.1) ||
      still_readings < 1 || discard_frames < 0 ||
      max_frames_per_view < still_readings + discard_frames + 1) {
    *why =
        "head sweep: still_rad and arrive_rad in (0, 0.1), still_readings >= 1, "
        "discard_frames >= 0, and room for them in max_frames_per_view";
    return false;
  }
  return true;
}

std::vector<Eigen::Vector2d> SweepGrid(const Eigen::Vector2d& centre,
                                       const Eigen::Vector2d& half_range, int count) {
  const double aspect = half_range.y() > 0.0 ? half_range.x() / half_range.y() : 1.0;
  const int columns =
      std::max(2, static_cast<int>(std::lround(std::sqrt(std::max(count, 4) * aspect))));
  const int rows = std::max(2, (std::max(count, 4) + columns - 1) / columns);
  std::vector<Eigen::Vector2d> angles;
  for (int r = 0; r < rows; ++r) {
    const double tilt = centre.y() + half_range.y() * (2.0 * r / (rows - 1) - 1.0);
    for (int k = 0; k < columns; ++k) {
      const int c = r % 2 == 0 ? k : columns - 1 - k;
      angles.emplace_back(centre.x() + half_range.x() * (2.0 * c / (columns - 1) - 1.0), tilt);
    }
  }
  return angles;
}

SweepResult SweepHead(PanTiltHead* head, FrameSource* source,
                      const std::vector<Eigen::Vector2d>& angles, const HeadSweepOptions& options) {
  SweepResult result;
  if (!options.Check(&result.failure)) return result;
  for (size_t i = 0; i < angles.size(); ++i) {
    const std::string where = "view " + std::to_string(i + 1) + " (pan " +
                              std::to_string(RadToDeg(angles[i].x())) + " deg, tilt " +
                              std::to_string(RadToDeg(angles[i].y())) + " deg): ";
    const HeadResult moved = head->MoveTo(angles[i].x(), angles[i].y());
    if (!moved.ok()) {
      result.failure = where + "the head refused to move: " + moved.message;
      return result;
    }
    int budget = options.max_frames_per_view;
    SweepView view;
    std::string failure;
    bool ok = WaitUntilStill(head, source, angles[i], options, &budget, &view.frame, &failure);
    for (int k = 0; ok && k <= options.discard_frames; ++k)
      ok = GrabOne(source, &view.frame, &budget, &failure);
    HeadResult read;
    if (ok) read = head->Read(&view.head);
    if (!ok || !read.ok()) {
      result.failure = where + (ok ? "head read failed: " + read.message : failure);
      return result;
    }
    result.views.push_back(std::move(view));
  }
  result.ok = true;
  return result;
}

}  // namespace linetrack
