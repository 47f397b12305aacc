#pragma once

#include <Eigen/Dense>

namespace vf {

/// One d-vector per agent: a d x n matrix whose column i belongs to agent i, in the world
/// frame. The aliases below say which quantity a matrix holds; they are the same type.
using AgentVectors = Eigen::MatrixXd;

/// Positions q [m].
using Positions = AgentVectors;
/// Velocities q' [m/s], or the difference quotients v_k = (q_{k+1} - q_k)/h of the scheme.
using Velocities = AgentVectors;
/// Unweighted momenta p (divided by e^{kappa t}; unit masses, so [m/s]).
using Momenta = AgentVectors;
/// Potential gradients grad_i V(q), one column per agent (the force on agent i is minus it).
using Gradients = AgentVectors;
/// Accelerations q'' = -kappa q' - grad V [m/s^2].
using Accelerations = AgentVectors;

/// A 3-vector used for momenta in both 2D and 3D (z = 0 and x = y = 0 respectively in 2D).
using Vector3 = Eigen::Vector3d;

}  // namespace vf
