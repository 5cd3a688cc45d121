// Queries of the view-invariant regions, and the bearing half-width of a camera's image.
#include <algorithm>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/free_space.h"
#include "models/plan_visibility.h"
#include "models/robot_pose.h"
#include "models/text_format.h"
#include "models/view_invariant_regions.h"

namespace linetrack {
namespace {

// Arcs of bearings (radians) or of diamond angles this close count as meeting: far above the
// rounding of their ends, and a diamond angle grows at most as fast as the bearing.
constexpr double kArcSlack = 1e-12;

// True when the arcs [centre_a +- half_a] and [centre_b +- half_b] (radians) meet modulo 2 pi.
bool ArcsMeet(double centre_a, double half_a, double centre_b, double half_b) {
  double d = centre_a - centre_b;
  d -= 2.0 * kPi * std::floor(d / (2.0 * kPi) + 0.5);  // to [-pi, pi), cheaper than remainder
  return std::abs(d) <= half_a + half_b + kArcSlack;
}

// Bearings of q - p for q on the footprint and p in the disk (centre, radius), as an arc
// (centre, half width); false when they take every value (the footprint meets the disk).
bool DiskBearings(const Segment2& footprint, const Eigen::Vector2d& centre, double radius,
                  double* arc_centre, double* arc_half) {
  if (DistanceToSegment(centre, footprint) <= radius + 1e-9) return false;
  // q - p ranges over the convex hull of two disks around the footprint's ends, which misses the
  // origin: its extreme bearings are the tangents to those disks.
  const Eigen::Vector2d mid = footprint.Mid() - centre;
  const double reference = std::atan2(mid.y(), mid.x());
  double lo = kPi, hi = -kPi;
  for (const Eigen::Vector2d& q : {footprint.a, footprint.b}) {
    const Eigen::Vector2d d = q - centre;
    const double towards = WrapAngle(std::atan2(d.y(), d.x()) - reference);
    const double spread = std::asin(std::min(1.0, radius / d.norm()));
    lo = std::min(lo, towards - spread);
    hi = std::max(hi, towards + spread);
  }
  if (hi - lo >= kPi) return false;
  *arc_centre = reference + 0.5 * (lo + hi);
  *arc_half = 0.5 * (hi - lo);
  return true;
}

}  // namespace

void ViewInvariantRegions::BuildGrid(const NavigableArea& area) {
  grid_.clear();
  if (regions_.empty()) return;
  grid_origin_ = area.BoundsMin();
  const Eigen::Vector2d extent = area.BoundsMax() - grid_origin_;
  // About one region per cell on average, cells no smaller than 5 cm.
  grid_cell_ = std::max(0.05, std::sqrt(extent.x() * extent.y() / regions_.size()));
  grid_cols_ = std::max(1, static_cast<int>(std::ceil(extent.x() / grid_cell_)));
  grid_rows_ = std::max(1, static_cast<int>(std::ceil(extent.y() / grid_cell_)));
  grid_.assign(static_cast<size_t>(grid_cols_) * grid_rows_, {});
  auto col = [&](double x) {
    return std::clamp(static_cast<int>(std::floor((x - grid_origin_.x()) / grid_cell_)), 0,
                      grid_cols_ - 1);
  };
  auto row = [&](double y) {
    return std::clamp(static_cast<int>(std::floor((y - grid_origin_.y()) / grid_cell_)), 0,
                      grid_rows_ - 1);
  };
  for (size_t r = 0; r < regions_.size(); ++r) {
    Eigen::Vector2d lo = regions_[r].polygon.vertices.front(), hi = lo;
    for (const Eigen::Vector2d& p : regions_[r].polygon.vertices) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (int j = row(lo.y()); j <= row(hi.y()); ++j) {
      for (int i = col(lo.x()); i <= col(hi.x()); ++i) {
        grid_[static_cast<size_t>(j) * grid_cols_ + i].push_back(static_cast<int>(r));
      }
    }
  }
}

std::vector<int> ViewInvariantRegions::Query(const VisibilityQuery& query) const {
  if (!query.centre.allFinite() || !std::isfinite(query.heading) ||
      !(query.radius >= 0.0 && std::isfinite(query.radius)) || !(query.heading_margin >= 0.0) ||
      !(query.bearing_half_width >= 0.0)) {
    throw InputError(
        "visibility query: centre and heading must be finite, radius, heading margin and "
        "bearing half-width >= 0");
  }
  std::vector<int> ids;
  if (grid_.empty()) return ids;
  const double x0 = (query.centre.x() - query.radius - grid_origin_.x()) / grid_cell_;
  const double x1 = (query.centre.x() + query.radius - grid_origin_.x()) / grid_cell_;
  const double y0 = (query.centre.y() - query.radius - grid_origin_.y()) / grid_cell_;
  const double y1 = (query.centre.y() + query.radius - grid_origin_.y()) / grid_cell_;
  // Regions stick out of their grid cells by rounding only: a disk beyond the grid meets none.
  if (x1 < -1e-9 || y1 < -1e-9 || x0 > grid_cols_ + 1e-9 || y0 > grid_rows_ + 1e-9) return ids;
  const int i0 = std::clamp(static_cast<int>(std::floor(x0)), 0, grid_cols_ - 1);
  const int i1 = std::clamp(static_cast<int>(std::floor(x1)), 0, grid_cols_ - 1);
  const int j0 = std::clamp(static_cast<int>(std::floor(y0)), 0, grid_rows_ - 1);
  const int j1 = std::clamp(static_cast<int>(std::floor(y1)), 0, grid_rows_ - 1);
  std::vector<int> candidates;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const std::vector<int>& cell = grid_[static_cast<size_t>(j) * grid_cols_ + i];
      candidates.insert(candidates.end(), cell.begin(), cell.end());
    }
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

  const int storey =
      std::isfinite(query.camera_z) && !storeys_.empty() ? StoreyAt(storeys_, query.camera_z) : -1;
  const double half = query.heading_margin + query.bearing_half_width;
  const bool any_bearing = half >= kPi;
  // The query's bearings [heading - half, heading + half] as an arc of diamond angles.
  const double query_min = BearingToDiamond(query.heading - half);
  const double query_width = WrapDiamond(BearingToDiamond(query.heading + half) - query_min);
  // The regions of the camera's storey that meet the disk: their union covers every position of
  // the query.
  std::vector<int> met;
  for (int r : candidates) {
    const ViewRegion& region = regions_[r];
    if (storey >= 0 && region.storey != storey) continue;
    if (DistanceToConvex(region.polygon.vertices, query.centre) > query.radius + 1e-9) continue;
    met.push_back(r);
  }
  Ring2 eyes;  // the hull of the positions, made when an edge first needs it
  // Per edge: 0 undecided, 1 kept, 2 dropped (its bearings from the disk miss the interval).
  std::vector<char> state(num_edges_, 0);
  for (int r : met) {
    const ViewRegion& region = regions_[r];
    for (const RegionEdge& e : region.visible) {
      if (state[e.edge_id] != 0) continue;
      if (any_bearing) {
        state[e.edge_id] = 1;
        continue;
      }
      if (!e.all_bearings && !DiamondArcsMeet(e.diamond_min, e.diamond_max - e.diamond_min,
                                              query_min, query_width, kArcSlack)) {
        continue;  // another region may still see it under the query's bearings
      }
      double arc_centre = 0.0, arc_half = 0.0;
      const bool narrow =
          DiskBearings(footprints_[e.edge_id], query.centre, query.radius, &arc_centre, &arc_half);
      const bool seen = !narrow || ArcsMeet(arc_centre, arc_half, query.heading, half);
      if (seen && eyes.empty()) eyes = EyesInDisk(query, met);
      state[e.edge_id] = seen && !HiddenFromDisk(query, half, storey, e.edge_id, eyes) ? 1 : 2;
    }
  }
  for (int id = 0; id < num_edges_; ++id) {
    if (state[id] == 1) ids.push_back(id);
  }
  return ids;
}

Ring2 ViewInvariantRegions::EyesInDisk(const VisibilityQuery& query,
                                       const std::vector<int>& met) const {
  const Ring2 disk = PolygonAroundDisk(query.centre, query.radius, 8);
  Ring2 points;
  for (int r : met) {
    Ring2 piece = regions_[r].polygon.vertices;
    for (size_t k = 0; k < disk.size() && !piece.empty(); ++k)
      piece = ClipConvex(piece, Line2::Through(disk[k], disk[(k + 1) % disk.size()]));
    points.insert(points.end(), piece.begin(), piece.end());
  }
  Ring2 hull;
  if (points.size() >= 3) ConvexHull(&points, &hull);
  // A hull of no area (a disk that grazes its regions) is replaced by the disk's polygon.
  return hull.size() >= 3 ? hull : disk;
}

bool ViewInvariantRegions::HiddenFromDisk(const VisibilityQuery& query, double half, int storey,
                                          int edge_id, const Ring2& eyes) const {
  // A piece of the footprint this short, or of the eyes this small, is not split further
  // (metres); at most 2^kMaxDepth pieces of each.
  constexpr double kMinPiece = 0.05;
  constexpr int kMaxDepth = 3;
  if (storey < 0 || storey >= static_cast<int>(storey_walls_.size())) return false;
  const StoreyWalls& walls = storey_walls_[storey];
  if (walls.hideable.empty() || !walls.hideable[edge_id]) return false;
  Segment2 part;
  if (!ClipToBearingWedge(footprints_[edge_id], query.centre, query.radius, query.heading, half,
                          &part)) {
    return true;  // no point of the edge under the query's bearings
  }
  // A piece is hidden from a piece of the eyes when one wall hides it from all of them (such a
  // wall crosses the sight line between their middles); the edge when every pair is, the larger
  // of the two halved where one wall does not: two walls meeting at a corner hide together what
  // neither hides alone.
  const auto hidden = [&](const Segment2& piece, const Ring2& from, int piece_depth, int from_depth,
                          const auto& self) -> bool {
    const Ring2 footprint = piece.Length() > 0.0 ? Ring2{piece.a, piece.b} : Ring2{piece.a};
    Eigen::Vector2d lo = from.front(), hi = lo, mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : from) {
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p), mean += p;
    }
    mean /= static_cast<double>(from.size());
    const bool by_wall = walls.grid.AlongEveryCell(mean, piece.Mid(), [&](int i) {
      if (HiddenByWall(from, footprint, walls.grid.segments()[i], walls.lines[i], hidden_margin_)) {
        return true;
      }
      return std::any_of(walls.corners[i].begin(), walls.corners[i].end(),
                         [&](const WallCorner& c) {
                           return HiddenByCorner(from, footprint, c.corner, c.far_self, c.far_other,
                                                 hidden_margin_);
                         });
    });
    if (by_wall) return true;
    const Eigen::Vector2d size = hi - lo;
    const bool split_piece = piece_depth < kMaxDepth && piece.Length() >= 2.0 * kMinPiece;
    const bool split_from = from_depth < kMaxDepth && size.maxCoeff() >= 2.0 * kMinPiece;
    if (split_piece && (!split_from || piece.Length() >= size.maxCoeff())) {
      return self({piece.a, piece.Mid()}, from, piece_depth + 1, from_depth, self) &&
             self({piece.Mid(), piece.b}, from, piece_depth + 1, from_depth, self);
    }
    Ring2 a, b;
    const Eigen::Vector2d axis =
        size.x() >= size.y() ? Eigen::Vector2d::UnitX() : Eigen::Vector2d::UnitY();
    if (!split_from || !SplitConvex(from, {axis, axis.dot(mean)}, 0.0, &a, &b)) return false;
    return self(piece, a, piece_depth, from_depth + 1, self) &&
           self(piece, b, piece_depth, from_depth + 1, self);
  };
  return hidden(part, eyes, 0, 0, hidden);
}

std::string ViewInvariantRegions::ExplainEmptyQuery(const VisibilityQuery& query) const {
  const int storey =
      std::isfinite(query.camera_z) && !storeys_.empty() ? StoreyAt(storeys_, query.camera_z) : -1;
  const std::string where =
      "(" + Fixed(query.centre.x()) + ", " + Fixed(query.centre.y()) + ") +- " +
      Fixed(query.radius) + " m" +
      (storey >= 0 && storeys_.size() > 1 ? " on storey " + std::to_string(storey) : std::string());
  int met = 0, listing = 0;
  for (const ViewRegion& region : regions_) {
    if ((storey >= 0 && region.storey != storey) ||
        DistanceToConvex(region.polygon.vertices, query.centre) > query.radius + 1e-9) {
      continue;
    }
    ++met;
    listing += region.visible.empty() ? 0 : 1;
  }
  if (regions_.empty()) return "the model has no navigable area to localise in";
  if (met == 0) return "the prior " + where + " lies outside the navigable area";
  if (listing == 0) return "no model edge is visible from the prior " + where;
  return "no model edge is visible from the prior " + where + " under headings " +
         Fixed(RadToDeg(query.heading), 1) + " +- " +
         Fixed(RadToDeg(query.heading_margin + query.bearing_half_width), 1) + " deg";
}

double BearingHalfWidth(const CameraIntrinsics& camera, double tilt_min, double tilt_max,
                        double roll) {
  std::string why;
  if (!camera.Check(&why)) throw InputError("camera " + camera.name + ": " + why);
  if (camera.width <= 0 || camera.height <= 0) {
    throw InputError("camera " + camera.name + ": the image size is needed for its field of view");
  }
  if (!(std::isfinite(tilt_min) && std::isfinite(tilt_max) && tilt_min <= tilt_max &&
        tilt_min >= -0.5 * kPi && tilt_max <= 0.5 * kPi)) {
    throw InputError("tilt interval: need -90 <= tilt_min <= tilt_max <= 90 degrees");
  }
  if (!std::isfinite(roll)) throw InputError("roll: not a finite number");
  // Box of the normalised coordinates (x, y) of the image's rays, de-rolled (UnrollImagePoint).
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  auto add = [&](const Eigen::Vector2d& m) {
    const Eigen::Vector2d unrolled = roll == 0.0 ? m : UnrollImagePoint(m, roll);
    lo = lo.cwiseMin(unrolled);
    hi = hi.cwiseMax(unrolled);
  };
  const Eigen::Vector2d far_corner(camera.width - 1.0, camera.height - 1.0);
  const Eigen::Vector2d m_lo = camera.Ray(Eigen::Vector2d::Zero()).head<2>();
  const Eigen::Vector2d m_hi = camera.Ray(far_corner).head<2>();
  if (!camera.has_distortion) {
    add(m_lo), add(m_hi), add({m_lo.x(), m_hi.y()}), add({m_hi.x(), m_lo.y()});
  } else {
    // The undistorted image of the border, sampled every pixel, grown by half a pixel.
    const Eigen::Vector2d half_pixel(0.5 / camera.px, 0.5 / camera.py);
    auto add_pixel = [&](double u, double v) {
      const Eigen::Vector2d m = camera.Ray(camera.Undistort({u, v})).head<2>();
      for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0})
          add(m + Eigen::Vector2d(sx * half_pixel.x(), sy * half_pixel.y()));
    };
    for (int u = 0; u < camera.width; ++u)
      add_pixel(u, 0.0), add_pixel(u, far_corner.y());
    for (int v = 0; v < camera.height; ++v)
      add_pixel(0.0, v), add_pixel(far_corner.x(), v);
  }
  // |w| = atan2(|m_x|, mL_z) with mL_z = cos t - sin t m_y grows with |m_x| and is monotone in
  // m_y and, where mL_z > 0, in t over an interval: the extreme is at a corner of the box and an
  // end of the tilt interval.
  const double x_abs = std::max(std::abs(lo.x()), std::abs(hi.x()));
  double widest = 0.0;
  for (double tilt : {tilt_min, tilt_max}) {
    for (double y : {lo.y(), hi.y()}) {
      const double z = std::cos(tilt) - std::sin(tilt) * y;
      if (z <= 0.0) return kPi;
      widest = std::max(widest, std::atan2(x_abs, z));
    }
  }
  return widest;
}

}  // namespace linetrack
