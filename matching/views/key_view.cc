#include "matching/views/key_view.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace linetrack {

std::vector<Segment2> KeyView::Images() const {
  std::vector<Segment2> out;
  out.reserve(segments.size());
  for (const ViewSegment& s : segments)
    out.push_back(s.image);
  return out;
}

void ComputeViewTokens(ViewDatabase* db) {
  std::vector<Eigen::Vector4d> sample;
  for (const KeyView& view : db->views) {
    const std::vector<Eigen::Vector4d> s = NeighbourSample(view.Images(), db->token_options);
    sample.insert(sample.end(), s.begin(), s.end());
  }
  db->equalisation = TokenEqualisation::Fit(sample);
  db->tokens.clear();
  for (const KeyView& view : db->views) {
    db->tokens.push_back(ComputeTokens(view.Images(), db->equalisation, db->token_options));
  }
}

bool KeyViewOptions::Check(std::string* why) const {
  if (!(min_length_px >= 0.0) ||
      !(min_junction_angle_deg >= 0.0 && min_junction_angle_deg < 90.0) ||
      !(vertex_tolerance_m > 0.0)) {
    *why =
        "key view options: min_length_px >= 0, min_junction_angle_deg in [0, 90), "
        "vertex_tolerance_m > 0";
    return false;
  }
  return true;
}

bool ViewGrid::Check(std::string* why) const {
  if (!(step > 0.0 && std::isfinite(step)) || !(heading_step > 0.0 && heading_step <= 2.0 * kPi) ||
      !(height > 0.0 && std::isfinite(height)) || !(std::abs(tilt) < kPi / 2.0)) {
    *why = "view grid: step > 0, heading step in (0, 360] degrees, height > 0, |tilt| < 90 degrees";
    return false;
  }
  return true;
}

KeyView KeyViewFromEdges(const WireframeModel& model, const std::vector<ProjectedEdge>& pieces,
                         const RobotPose& pose, const KeyViewOptions& options) {
  KeyView view;
  view.pose = pose;
  std::vector<ProjectedEdge> kept;
  for (const ProjectedEdge& p : pieces) {
    if (p.image.Length() < options.min_length_px) continue;
    view.segments.push_back({p.image, p.edge_id});
    kept.push_back(p);
  }
  view.junctions = VertexJunctions(model, kept, options);
  return view;
}

namespace {

// The image endpoint of `piece` at vertex v (world position within tolerance), if any.
std::optional<Eigen::Vector2d> EndAtVertex(const ProjectedEdge& piece, const Eigen::Vector3d& v,
                                           double tolerance) {
  if ((piece.world.a - v).norm() <= tolerance) return piece.image.a;
  if ((piece.world.b - v).norm() <= tolerance) return piece.image.b;
  return std::nullopt;
}

// Angle (radians, [0, pi/2]) between two segments' lines.
double LineAngle(const Segment2& a, const Segment2& b) {
  const Eigen::Vector2d da = (a.b - a.a).normalized(), db = (b.b - b.a).normalized();
  return std::acos(std::min(1.0, std::abs(da.dot(db))));
}

}  // namespace

std::vector<ViewJunction> VertexJunctions(const WireframeModel& model,
                                          const std::vector<ProjectedEdge>& pieces,
                                          const KeyViewOptions& options) {
  // Pieces ending at each vertex of their edge.
  std::map<int, std::vector<std::pair<int, Eigen::Vector2d>>> at_vertex;  // vertex -> (piece, px)
  for (size_t i = 0; i < pieces.size(); ++i) {
    const ModelEdge& edge = model.edges()[pieces[i].edge_id];
    for (int v : {edge.v0, edge.v1}) {
      const auto end = EndAtVertex(pieces[i], model.vertices()[v], options.vertex_tolerance_m);
      if (end) at_vertex[v].emplace_back(static_cast<int>(i), *end);
    }
  }
  std::vector<ViewJunction> out;
  const double min_angle = DegToRad(options.min_junction_angle_deg);
  for (const auto& [vertex, ends] : at_vertex) {
    ViewJunction junction;
    junction.point_id = vertex;
    junction.pixel = ends.front().second;
    bool wide = false;
    for (size_t a = 0; a < ends.size(); ++a) {
      const ProjectedEdge& pa = pieces[ends[a].first];
      if (std::find(junction.lines.begin(), junction.lines.end(), pa.edge_id) ==
          junction.lines.end()) {
        junction.lines.push_back(pa.edge_id);
      }
      for (size_t b = a + 1; b < ends.size(); ++b) {
        const ProjectedEdge& pb = pieces[ends[b].first];
        wide = wide || (pa.edge_id != pb.edge_id && LineAngle(pa.image, pb.image) >= min_angle);
      }
    }
    if (wide) out.push_back(std::move(junction));
  }
  return out;
}

std::vector<RobotPose> GridPoses(const NavigableArea& area, const ViewGrid& grid) {
  std::vector<RobotPose> out;
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  const int headings =
      std::max(1, static_cast<int>(std::floor(2.0 * kPi / grid.heading_step + 1e-9)));
  // Grid lines on multiples of the step, so that grids of one step line up across models.
  const int ix0 = static_cast<int>(std::ceil(lo.x() / grid.step - 1e-9));
  const int iy0 = static_cast<int>(std::ceil(lo.y() / grid.step - 1e-9));
  for (int iy = iy0; iy * grid.step <= hi.y() + 1e-9; ++iy) {
    for (int ix = ix0; ix * grid.step <= hi.x() + 1e-9; ++ix) {
      const double x = ix * grid.step, y = iy * grid.step;
      if (!area.Contains({x, y})) continue;
      for (int h = 0; h < headings; ++h) {
        out.push_back({x, y, h * grid.heading_step, grid.height, grid.tilt});
      }
    }
  }
  return out;
}

}  // namespace linetrack
