#pragma once

#include <Eigen/Dense>

namespace vf {

/// Stacked agent positions (or velocities, momenta, gradients): a d x n matrix whose column i
/// is agent i, in the world frame, in metres (per second for velocities).
using Positions = Eigen::MatrixXd;

/// A 3-vector used for momenta in both 2D and 3D (z = 0 and x = y = 0 respectively in 2D).
using Vector3 = Eigen::Vector3d;

}  // namespace vf
