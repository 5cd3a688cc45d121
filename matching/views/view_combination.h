// Positioning by the linear combination of two model views under weak perspective (seed 002,
// section 3, after Ullman and Basri 1991 and Basri and Rivlin 1993), derived in docs/views.md.
// Coordinates are normalised image coordinates (x = (u - u0) / px, unit focal length); the
// object frame is model view 1's camera frame, scaled by the reference depth Z0 and centred on
// its optical axis at Z0: p = (X - (0, 0, Z0)) / Z0, so that view 1 sees (x1, y1) = (p_x, p_y).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

namespace linetrack {

// A weak-perspective view of the object frame: (x, y) = scale * rotation.topRows(2) * p +
// translation (eq. 1).
struct WeakPerspective {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // camera from view-1 camera
  double scale = 1.0;
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
};

// The weak-perspective view of a camera with `rotation` (camera from view-1 camera) and centre
// `centre` (view-1 camera frame, metres), for reference depth z0: with o = rotation ((0, 0, z0)
// - centre), scale = z0 / o_z and translation = (o_x, o_y) / o_z. nullopt when o_z <= 0.
std::optional<WeakPerspective> WeakPerspectiveOf(const Eigen::Matrix3d& rotation,
                                                 const Eigen::Vector3d& centre, double z0);

// The mean depth in view 1 (metres) of the points seen in both model views, each triangulated
// from the two views' rays (normalised coordinates; view 2 at `rotation`, `centre` in view 1's
// frame) by the midpoint of their common perpendicular: the seed's Z0, "the average distance of
// the camera in P1 to the scene". Points behind either camera or on near-parallel rays are
// skipped; nullopt when none is left.
std::optional<double> MeanTriangulatedDepth(const std::vector<Eigen::Vector2d>& view1,
                                            const std::vector<Eigen::Vector2d>& view2,
                                            const Eigen::Matrix3d& rotation,
                                            const Eigen::Vector3d& centre);

// Eq. 4: x' = a1 x1 + a2 y1 + a3 x2 + a4 and y' = b1 x1 + b2 y1 + b3 x2 + b4 by least squares.
struct ViewCombination {
  Eigen::Vector4d a = Eigen::Vector4d::Zero(), b = Eigen::Vector4d::Zero();
  double rms = 0.0;  // residual (normalised units)
};
// nullopt with fewer than 4 points or a rank-deficient basis (x2 in the span of x1, y1, 1: no
// rotation about view 1's y axis between the model views). Inputs of equal sizes.
std::optional<ViewCombination> FitViewCombination(const std::vector<Eigen::Vector2d>& view1,
                                                  const std::vector<double>& view2_x,
                                                  const std::vector<Eigen::Vector2d>& novel);

// The novel view recovered from the coefficients (eqs. 9-13): s_n U_1 = (a1 + a3 s r11,
// a2 + a3 s r12, a3 s r13), s_n U_2 likewise with the b's (the seed's eq. 13 writes r2j there:
// it must be r1j, since the third basis vector is x2), t_n = (a3 t_x + a4, b3 t_x + b4).
struct NovelView {
  double scale_a = 0.0, scale_b = 0.0;  // |s_n U_1| (eq. 10) and |s_n U_2| (eq. 11)
  double orthogonality = 0.0;           // cosine of the angle between U_1 and U_2
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // U orthonormalised, det +1
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // view-1 camera frame, metres
};
// `view2` is model view 2's weak perspective at z0 (WeakPerspectiveOf).
NovelView RecoverNovelView(const ViewCombination& combination, const WeakPerspective& view2,
                           double z0);

}  // namespace linetrack
