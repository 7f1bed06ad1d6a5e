// Analytic Jacobians of the generalized forces of a spatial Model's force
// elements: translational spring-damper-actuators (linear or tabulated),
// point forces and torques (body or world directions), rotational
// spring-dampers and bushings, for SpatialSystem's Newton matrix and its
// exact state Jacobian (docs/physics.md section 8, "Newton matrix").
// Gravity's force is constant and adds nothing.
#pragma once

#include <Eigen/Dense>

#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

// Adds dQ/dq and dQ/dv of the force elements at (t, q, v) into the n x n
// matrices (SpatialSystem's layout). `continued`: force curves past their
// tables along their end segments, as SpringTension, and bushings past
// their middle-angle limit. `angles` follows the rotational springs' turns
// as the forces do (their Jacobian is atan2's: the turn count is locally
// constant). 0, or 1 when a spring has zero length, a bushing is past its
// angle limit outside a continued scope, or a value is not finite.
int AddElementJacobians(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                        bool continued, SpringAngles* angles, Eigen::MatrixXd* q_q, Eigen::MatrixXd* q_v);

}  // namespace mbopt::spatial
