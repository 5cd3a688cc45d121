#include "models/render/kidnap.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

namespace {

// The base or camera pose moved by the carry: position and heading.
void MovePlanar(const Eigen::Isometry3d& carry, double turn, RobotPose* pose) {
  const Eigen::Vector3d p = carry * Eigen::Vector3d(pose->x, pose->y, 0.0);
  pose->x = p.x();
  pose->y = p.y();
  pose->heading = WrapAngle(pose->heading + turn);
}

}  // namespace

Eigen::Isometry3d PlanarCarry(const Pose3Dof& from, const Pose3Dof& to) {
  const double turn = to.heading - from.heading;
  Eigen::Isometry3d w = Eigen::Isometry3d::Identity();
  w.linear() = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  w.translation() =
      Eigen::Vector3d(to.x, to.y, 0.0) - w.linear() * Eigen::Vector3d(from.x, from.y, 0.0);
  return w;
}

Kidnap ParseKidnap(const std::string& text) {
  const std::string where = "--kidnap '" + text + "': ";
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw InputError(where + "expected FRAME:x,y,heading_deg");
  Kidnap k;
  size_t used = 0;
  try {
    k.frame = std::stoi(text.substr(0, colon), &used);
  } catch (const std::exception&) {
    used = std::string::npos;
  }
  if (used != colon) throw InputError(where + "the frame is not an integer");
  std::istringstream in(text.substr(colon + 1));
  double v[3];
  char comma1 = 0, comma2 = 0;
  in >> v[0] >> comma1 >> v[1] >> comma2 >> v[2];
  if (!in || comma1 != ',' || comma2 != ',' || !(in >> std::ws).eof() || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    throw InputError(where + "expected FRAME:x,y,heading_deg with three finite numbers");
  }
  k.put_down = Pose3Dof{v[0], v[1], DegToRad(v[2])};
  return k;
}

std::vector<SequenceFrame> ApplyKidnaps(std::vector<SequenceFrame> frames,
                                        const std::vector<Kidnap>& kidnaps,
                                        const NavigableArea* area) {
  int previous = 0;
  for (const Kidnap& k : kidnaps) {
    if (k.frame <= previous || k.frame >= static_cast<int>(frames.size())) {
      throw InputError("--kidnap " + std::to_string(k.frame) + ": the frame must be in [1, " +
                       std::to_string(frames.size()) + ") and after the previous kidnap");
    }
    previous = k.frame;
    const Pose3Dof from = frames[k.frame].base.Planar();
    const Eigen::Isometry3d carry = PlanarCarry(from, k.put_down);
    const double turn = k.put_down.heading - from.heading;
    for (size_t f = k.frame; f < frames.size(); ++f) {
      SequenceFrame& frame = frames[f];
      MovePlanar(carry, turn, &frame.base);
      MovePlanar(carry, turn, &frame.camera);
      frame.cam_from_world = frame.cam_from_world * carry.inverse();
    }
  }
  if (area == nullptr) return frames;
  size_t next = 0;  // the kidnap that moved each frame
  for (size_t f = kidnaps.empty() ? frames.size() : kidnaps[0].frame; f < frames.size(); ++f) {
    while (next + 1 < kidnaps.size() && static_cast<int>(f) >= kidnaps[next + 1].frame)
      ++next;
    const RobotPose& base = frames[f].base;
    if (!area->Contains(Eigen::Vector2d(base.x, base.y))) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    ": the drive put down there leaves the navigable area near (%.2f, %.2f) on "
                    "frame %zu",
                    base.x, base.y, f);
      throw InputError("--kidnap " + std::to_string(kidnaps[next].frame) + text);
    }
  }
  return frames;
}

}  // namespace linetrack
