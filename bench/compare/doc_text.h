// The fixed prose of docs/comparison.md: how the comparison is set up and
// why the methods differ. Numbers are never written here; they come from
// the runs.
#pragma once

namespace mbopt::compare {

inline constexpr char kProtocol[] = R"(## Protocol

- **Same problem for every method.** Each study file is loaded as the service loads it; every
  method analyses designs with the same engine call (`local_run::EvaluateDesign`) on the same
  scaled design variables and bounds, and sees the same constraint rows normalized as
  (g - c) / scale <= 0 (METHOD.md's g/c - 1). With `--scene-grid` (the command above) every
  study runs on its scene's own time grid: the four-bars on the report's 101 instants, not the
  1001 their study files use (MMA treats each of the 32 000 rows of the fine grid as its own
  constraint and needs minutes per iteration there); docs/results.md has the 1001-point runs.
- **mbopt SLP**: `local_run::RunStudyLocally` with the study's own optimizer settings (the
  defaults of METHOD.md section 3): adaptive move limits, forward differences, CLP for the LPs.
- **NLopt SLSQP** (`NLOPT_LD_SLSQP`) and **NLopt MMA** (`NLOPT_LD_MMA`), NLopt 2.7 from Debian,
  set up as a user would: gradients by forward differences with exactly the SLP core's step rule
  (`slp::PlanSteps`, forward scheme, step 1e-4 max(|x|, 1 % of the range), backwards at an
  upper bound, one retry after a failed perturbation); the objective divided by |F(x0)|; a
  min-max objective in the same bound formulation the SLP uses (an extra variable b in
  [-10, 10]: minimize b subject to f_i / |F(x0)| - b <= 0), so the peers see a smooth problem;
  stopping at ftol_rel = xtol_rel = 1e-6, at the study's `objective_target` if it has one (NLopt's
  stopval, as the SLP stops there), or when the next request would exceed the analysis cap;
  constraint tolerance 1e-6 on the normalized rows (NLopt returns the best point it saw that
  meets every row within it; with 0, finite-difference noise of 1e-12 at an active row made
  SLSQP return an early, strictly feasible design far from the optimum).
  NLopt asks for the gradient with every function value (line-search and inner points too), so
  each NLopt evaluation costs 1 + n analyses. A design whose analysis fails is reported to the
  peer as a large constraint violation and objective.
- **Counting.** Every engine analysis counts (a gradient costs n). A method *reaches the target*
  at the first candidate design it analysed (the initial design, SLP trial points, NLopt's
  evaluation points; never a finite-difference perturbation) whose objective is within 0.5 %
  of the best known objective F* and whose max normalized violation is at most 0.2 %. F* is the
  lowest objective any of the methods analysed at a design feasible within 0.2 %; where F* is
  near zero (landing gear) the 0.5 % is taken of max(|F*|, 1 % of |F(x0)|). "final" is the
  design each method returns. Wall time is the whole run on one core, analyses included.
)";

inline constexpr char kDiscussion[] = R"(## Why the methods differ

- **Cost of a gradient.** All three pay n analyses per forward-difference gradient. The SLP
  asks for one gradient per cycle and one analysis per trial point; a rejected trial costs one
  analysis. NLopt's SLSQP and MMA evaluate the gradient at every point they visit, including
  line-search points (SLSQP) and inner conservative iterations (MMA), so a step that the SLP
  would reject for one analysis costs them 1 + n. With simulator sensitivities this difference
  would shrink; no method here uses them (see docs/accuracy.md).
- **Many constraint rows.** The time-dependent constraints become hundreds to thousands of rows
  (vehicle: 1010 rows plus 202 objective terms; four-bar: 3232 rows). The SLP screens rows far
  from their limits out of each LP; SLSQP carries every row in its quadratic subproblem and MMA
  in its dual, which costs time (not analyses).
- **Convergence test.** The SLP stops when a cycle changes F by less than 0.5 % at a design
  feasible within 0.5 % (METHOD.md section 3). That is loose next to the 0.5 %-of-F* target when
  the last cycles creep: where the SLP ends a few tenths of a percent above F* (and with slack
  in every constraint), a peer that keeps going wins on the final F. NLopt stops on a relative
  change of 1e-6, so it spends more analyses polishing the last digits. "analyses to target" is
  the fair measure of speed; "total analyses" includes each method's own stopping rule.
- **MMA's approximations.** MMA (NLopt implements Svanberg's globally convergent version) builds convex, separable
  approximations with moving asymptotes and makes them more conservative until the new point
  improves on them. Where that model fits (responses monotone in each variable) it reaches the
  target in few outer iterations; its inner iterations each cost a full gradient here, so it
  wins on analyses only where it needs few of them.
- **"FAILURE" and "ROUNDOFF_LIMITED"** in the end column are NLopt's own return codes: the
  method gave up (SLSQP does so when its line search or its quadratic subproblem fails, which
  inaccurate finite-difference gradients can cause) and returned the best point it had.
- **Noise from the analyses.** Time-integrated outputs carry the integrator's error (relative
  tolerance 1e-8 in the vehicle scene, 1e-6 in the elastic four-bar), and forward differences
  with step 1e-4 amplify it. Quasi-Newton methods such as SLSQP build curvature from gradient
  differences, which such noise can spoil; the SLP needs first-order information only. This
  comparison does not isolate that effect.
)";

}  // namespace mbopt::compare
