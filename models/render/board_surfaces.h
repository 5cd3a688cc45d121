// A chessboard as render surfaces (render_scene.h), for the simulated camera to see a calibration
// board: a light board and its dark squares painted on it as decals. Board frame as
// calibration/pattern.h has it: origin at the first inner corner, x along a row, y down the
// columns, z = 0 on the board; squares span [-s, cols s] x [-s, rows s] and the one at the
// origin's upper left is dark (tests/support/synthetic_board.h draws the same board).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "models/render/render_scene.h"

namespace linetrack {

struct ChessboardSurfaceOptions {
  int cols = 9, rows = 6;       // inner corners
  double square = 0.04;         // metres
  double margin_squares = 1.0;  // light border beyond the squares
  double light_albedo = 0.85, dark_albedo = 0.06;
};

// The board placed at `world_from_board`: the light board first, then one decal per dark square.
std::vector<RenderSurface> ChessboardSurfaces(const Eigen::Isometry3d& world_from_board,
                                              const ChessboardSurfaceOptions& options);

}  // namespace linetrack
