// Which settings the accuracy sweep runs for a reference problem: one knob at
// a time around the study's own settings (the default), plus the tight
// reference run and the fine re-check every found design gets.
//
// Knobs: AnalysisOverrides (time grid points, integrator relative tolerance
// with the absolute tolerance kept at 1e-3 times it, elements per flexible
// link, rigid links) and the optimizer's finite-difference scheme and
// relative step.
#pragma once

#include <string>
#include <vector>

#include "mbopt/v1/study.pb.h"

namespace mbopt::accuracy {

// Model knobs choose the model that is solved (grid, mesh, link model) and
// are judged against the reference; solver knobs choose how accurately that
// model is solved and differentiated (tolerance, finite differences) and
// are judged against the default run, which solves the same model.
enum class KnobKind { kDefault, kModel, kSolver };

struct Setting {
  KnobKind kind = KnobKind::kDefault;
  std::string knob;   // e.g. "time grid points"; "default" for the study's own
  std::string value;  // e.g. "201"
  v1::AnalysisOverrides analysis;
  v1::OptimizerOptions optimizer;
};

struct SweepPlan {
  std::string problem;     // vehicle, fourbar_rigid, fourbar_elastic, landing_gear
  std::string study_file;  // relative to the repository root
  std::vector<Setting> settings;  // the default first
  Setting reference;       // finest grid, tightest tolerance, finest mesh
  // The fine re-check of a found design: a grid at least as fine as the
  // reference's (where the grid matters), the reference's tolerance and mesh.
  v1::AnalysisOverrides recheck;
  std::string recheck_note;  // what `recheck` is, for the page
  std::vector<std::string> not_swept;  // knobs that do not apply, with why
  // Scaled initial design replacing the study's (a warm start for a problem
  // too expensive to optimize from the study's start once per setting).
  std::vector<double> initial_override;
  std::string initial_note;
  // True when the reference solves the default's model (it differs in solver
  // knobs only): solver knobs are then judged against the reference too.
  bool reference_is_default_model = false;
};

// The known problems, in report order.
std::vector<std::string> ProblemNames();

// False if `problem` is unknown.
bool MakeSweepPlan(const std::string& problem, SweepPlan* plan);

}  // namespace mbopt::accuracy
