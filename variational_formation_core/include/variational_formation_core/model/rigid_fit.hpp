#pragma once

#include "variational_formation_core/common/types.hpp"

namespace vf {

/// A rigid motion x -> R x + t of R^d, and how well it maps one point set onto another.
struct RigidFit {
  Eigen::MatrixXd rotation;     ///< R, d x d orthogonal [1]
  Eigen::VectorXd translation;  ///< t [m]
  bool reflection = false;      ///< det R = -1
  double squaredResidual = 0;   ///< sum_i |R b_i + t - a_i|^2 [m^2]
};

/**
 * Orthogonal Procrustes (Kabsch): the R and t minimising sum_i |R b_i + t - a_i|^2 over
 * rotations, or over all orthogonal R if allowReflection. With centroids a-bar, b-bar and
 * H = sum_i (b_i - b-bar)(a_i - a-bar)^T = U S V^T, R = V diag(1, .., 1, s) U^T with
 * s = sign det(V U^T) (s = 1 if reflections are allowed), t = a-bar - R b-bar.
 * @param target a, d x n [m]; @param source b, d x n [m], same size.
 */
RigidFit fitRigidMotion(const Positions& target, const Positions& source, bool allowReflection);

/**
 * Whether q is a mirror image of the desired shape q* rather than a rotated copy: the best
 * orthogonal fit of q* onto q (fitRigidMotion with reflections allowed) is a reflection, and q*
 * is not flat. A shape is flat (collinear in 2D, planar in 3D) when its smallest principal
 * extent (singular value of the centred points) is at most `flatness` times its largest; a flat
 * shape is its own mirror image. Meaningful for shapes close to congruent with q*; scale-free.
 */
bool isMirrorImage(const Positions& q, const Positions& desired, double flatness = 0.01);

}  // namespace vf
