// Analytic Jacobians of the generalized forces of a spatial Model's
// translational spring-damper-actuators (linear or tabulated), point forces
// and torques (body or world directions), for SpatialSystem's Newton matrix
// and its exact state Jacobian (docs/physics.md section 8, "Newton
// matrix"). Gravity's force is constant and adds nothing. Rotational
// spring-dampers and bushings have none here: a model with one is
// differenced (SpatialSystem::ForceJacobians) and has no exact state
// Jacobian.
#pragma once

#include <Eigen/Dense>

#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

// Whether every force element of the model has an analytic Jacobian below.
bool HasAnalyticElementJacobians(const Model& model);

// Adds dQ/dq and dQ/dv of the springs, point forces and torques at
// (t, q, v) into the n x n matrices (SpatialSystem's layout). `continued`:
// force curves past their tables along their end segments, as
// SpringTension. 0, or 1 when a spring has zero length or a value is not
// finite.
int AddElementJacobians(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                        bool continued, Eigen::MatrixXd* q_q, Eigen::MatrixXd* q_v);

}  // namespace mbopt::spatial
