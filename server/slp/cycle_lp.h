// The LP of one SLP cycle (METHOD.md section 2.4): the move-limit box,
// screening, and the linear program in the step d = x - x0, with the bound
// variables beta_g of a min-max objective or a sum of maxima, and the
// infeasibility variable s.
// Pure: builds an lp::LinearProgram and reads its solution back.
//
// LP columns: d_0..d_{n-1}, then beta'_g (one per objective group; none for a
// scalar objective), then s. Scaled so that every row is dimensionless:
//   objective (scalar):  minimize grad F . d / S + penalty * s
//   objective (groups):  minimize sum_g beta'_g + penalty * s, with one row per
//                        kept term j of group g:
//                        (f_j0 + grad f_j . d - M_g0) / S <= beta'_g
//   constraint h kept:   (g_h0 + grad g_h . d - c_h) / scale_h <= s
// where M_g0 is group g's largest term at x0 (F0 for min-max) and
// S = max(|F0|, sum_g max_{kept j in g} sum_i |grad f_j,i| w_i,
// objective_magnitude_floor) is the objective's scale, so the objective can
// change by at most about 1 inside the box and the penalty dominates it.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "server/lp/linear_program.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"

namespace mbopt::slp {

// Values and first derivatives of every response at x0.
struct Linearization {
  Eigen::VectorXd x0;
  Eigen::VectorXd terms0;        // objective terms f_j(x0)
  Eigen::VectorXd constraints0;  // g_h(x0)
  Eigen::MatrixXd terms_gradient;        // K x n
  Eigen::MatrixXd constraints_gradient;  // m x n
  std::vector<bool> frozen;      // variables held at x0 this cycle
};

// The box of this LP for the step d: half-width w_i = f_i * max(|x0_i|,
// floor_fraction * (upper_i - lower_i)), clipped to the bounds.
struct MoveBox {
  Eigen::VectorXd half_width;  // w_i (0 for a frozen variable)
  Eigen::VectorXd d_lower;     // max(lower - x0, -w)
  Eigen::VectorXd d_upper;     // min(upper - x0, w)
};

MoveBox ComputeMoveBox(const ProblemSpec& spec, const SlpOptions& options,
                       const Eigen::VectorXd& x0, const Eigen::VectorXd& move_limits,
                       const std::vector<bool>& frozen);

struct CycleLp {
  lp::LinearProgram lp;
  std::vector<int> kept_constraints;  // row h of the spec for each constraint row
  std::vector<int> kept_terms;        // objective term j for each term row (groups)
  std::vector<int> kept_term_groups;  // its group, one per kept term
  int beta_column = -1;               // the first group's beta'; -1 for a scalar objective
  int s_column = -1;
  double objective_scale = 1;  // S
};

CycleLp BuildCycleLp(const ProblemSpec& spec, const SlpOptions& options,
                     const Linearization& lin, const MoveBox& box);

// First-order optimality of the cycle's LP solution, dimensionless (>= 0;
// +infinity when the LP needed its infeasibility variable s, i.e. the
// linearized constraints cannot all be met inside the box).
//
// At the LP's optimum the gradient of the objective (with bound
// variables, of the terms weighted by their multipliers) plus the constraint gradients
// weighted by theirs is balanced by the reduced costs of the step columns d_i.
// A reduced cost on a design bound that x0 is on is a bound multiplier of
// the problem itself (counted only if of the wrong sign); one on a side of
// the box set by a move limit, or on a bound that the box reaches while x0
// is away from it, is gradient that x0 could still follow: the stationarity
// residual of the KKT conditions. Per variable it is
// made relative as the move limit is:
//   r_i = |reduced cost_i| * S * max(|x0_i|, floor_fraction * range_i) / max(|F0|, floor)
// i.e. the relative change of F per unit of the relative move limit f_i that
// the linearization still offers along x_i. Complementarity is measured at x0:
//   c = S * sum_rows |multiplier_r| * max(0, slack_r(x0)) / max(|F0|, floor)
// with slack (M_g0 - f_j(x0)) / S for a term of group g and (c_h - g_h(x0)) /
// scale_h for a constraint: a row that holds the LP's optimum must be active
// at x0 too, or that optimum lies away from x0. The residual is
// max(max_i r_i, c); 0 at a KKT point of the linearized problem at x0.
double OptimalityResidual(const ProblemSpec& spec, const SlpOptions& options,
                          const Linearization& lin, const MoveBox& box, const CycleLp& cycle_lp,
                          const lp::LpSolution& solution);

// The linear prediction of F at the step d: per group, the largest of
// f_j0 + grad f_j . d over the kept terms of the LP (or all terms without
// one), summed over the groups.
double PredictedObjective(const ProblemSpec& spec, const Linearization& lin, const Eigen::VectorXd& d,
                          const CycleLp* cycle_lp);

}  // namespace mbopt::slp
