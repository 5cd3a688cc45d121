// ViSP's pose files, for starting the tracker without the matcher: the ".0.pos" pose vector
// (tx ty tz tux tuy tuz: metres and a theta-u rotation in radians, vpPoseVector) and the 4x4
// homogeneous matrix (16 numbers, row-major, as in visp-images-data CameraPose/*.txt). Both hold
// cMo, i.e. cam_from_world.
#pragma once

#include <Eigen/Geometry>
#include <string>

namespace linetrack {

// cam_from_world from a theta-u pose vector: R = exp([tu]x) (Rodrigues), t as given.
Eigen::Isometry3d CamFromWorldFromPoseVector(const Eigen::Matrix<double, 6, 1>& pose_vector);

// Parses the text of a pose file: exactly 6 numbers (pose vector) or 16 numbers (4x4 matrix
// whose last row must be 0 0 0 1 and whose rotation must be orthonormal within 1e-4; it is
// re-orthonormalised). `path` names the file in errors. Throws InputError.
Eigen::Isometry3d ParsePoseText(const std::string& text, const std::string& path);

// Reads a pose file from disk (throws InputError naming the file).
Eigen::Isometry3d ReadPoseFile(const std::string& path);

}  // namespace linetrack
