// The deformed centre line of a co-rotational beam element (beam_element.h)
// as its own formulation sees it: along the chord between its nodes, the
// small bending displacement the element's end rotations theta_a, theta_b
// (relative to the chord) give by the cubic Hermite shape functions,
//
//   w(xi) = l (theta_a (xi - 2 xi^2 + xi^3) + theta_b (xi^3 - xi^2)),
//
// xi = s / l along the current chord of length l, w along its left normal.
// For a drawing: the points strictly between the nodes (the nodes are the
// mechanism's own coordinates). Pure.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "worker/multibody/mechanism.h"

namespace mbopt::multibody {

// Appends to `out` the `inner_points` points of element `element` of
// `mechanism` at xi = 1 / (inner_points + 1), 2 / (inner_points + 1), ...,
// at the coordinates `q`; false (nothing appended) if its nodes coincide.
bool AppendBeamInnerPoints(const Mechanism& mechanism, int element, const Eigen::VectorXd& q, int inner_points,
                           std::vector<Eigen::Vector2d>* out);

}  // namespace mbopt::multibody
