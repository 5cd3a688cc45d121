#include "models/render/board_surfaces.h"

namespace linetrack {
namespace {

RenderSurface Rectangle(const Eigen::Isometry3d& world_from_board, double x0, double y0, double x1,
                        double y1, double albedo) {
  RenderSurface s;
  s.kind = SurfaceKind::kBoard;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                                   Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)}) {
    s.polygon.push_back(world_from_board * Eigen::Vector3d(c.x(), c.y(), 0.0));
  }
  s.normal = world_from_board.linear().col(2);
  s.offset = s.normal.dot(world_from_board.translation());
  s.albedo = albedo;
  return s;
}

}  // namespace

std::vector<RenderSurface> ChessboardSurfaces(const Eigen::Isometry3d& world_from_board,
                                              const ChessboardSurfaceOptions& options) {
  const double s = options.square;
  const double m = s * (1.0 + options.margin_squares);
  std::vector<RenderSurface> surfaces = {
      Rectangle(world_from_board, -m, -m, (options.cols - 1) * s + m, (options.rows - 1) * s + m,
                options.light_albedo)};
  // Square (i, j) spans [(i - 1) s, i s] x [(j - 1) s, j s]; dark when i + j is even.
  for (int j = 0; j <= options.rows; ++j) {
    for (int i = 0; i <= options.cols; ++i) {
      if ((i + j) % 2 != 0) continue;
      RenderSurface square =
          Rectangle(world_from_board, (i - 1) * s, (j - 1) * s, i * s, j * s, options.dark_albedo);
      square.decal = true;
      surfaces.push_back(square);
    }
  }
  return surfaces;
}

}  // namespace linetrack
