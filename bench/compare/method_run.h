// What one optimization method did on one study, in the terms the comparison
// table needs: every candidate design it analysed (not finite-difference
// perturbations) with the analysis count at that moment, its final design's
// values, the analyses it spent and its wall time.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "server/slp/options.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::compare {

// One analysed candidate design: F (objective unit) and the largest
// normalized constraint violation max_h (g_h - c_h) / scale_h (0 if none).
struct Candidate {
  std::int64_t analyses = 0;  // analyses spent up to and including this one
  double objective = 0;
  double max_violation = 0;
};

struct MethodRun {
  std::string method;
  std::string study;
  std::vector<Candidate> candidates;
  double final_objective = 0;
  double final_max_violation = 0;
  std::int64_t analyses = 0;
  std::int64_t failed_analyses = 0;
  double wall_seconds = 0;
  std::string end;  // how it ended, e.g. "converged", "cap reached"
  // The SLP: cycles and rejected trial points. NLopt: its evaluations (each
  // 1 + n analyses with the gradient).
  int cycles = 0;
  int rejected_trials = 0;
  int evaluations = 0;
  int num_variables = 0;
};

// The study's analyses as an optimizer sees them, counted: values at scaled
// x and forward-difference Jacobians with the SLP core's step rule
// (slp::PlanSteps with the forward scheme and slp::RetryStep after a failed
// perturbation), so every method pays the same price for a gradient.
class CountedStudy {
 public:
  struct Point {
    bool ok = false;
    std::string failure_reason;
    Eigen::VectorXd terms;        // objective terms (F = max for min-max)
    Eigen::VectorXd normalized;   // (g_h - c_h) / scale_h per row
    double objective = 0;
    double max_violation = 0;
  };

  CountedStudy(const spec::Study& study, spec::StudyLayout layout, slp::SlpOptions fd_options);

  // Analyses x (one analysis). InvalidArgument only for an engine/layout
  // mismatch; a failed analysis is Point::ok == false.
  absl::StatusOr<Point> Evaluate(const Eigen::VectorXd& x);

  // Forward-difference derivatives at x0 (whose values are `at_x0`) of the
  // terms (d_terms, terms x n) and of the normalized rows (d_rows, rows x n):
  // n analyses (plus one retry per failed perturbation). A variable whose
  // perturbations fail twice gets a zero column.
  absl::Status Jacobians(const Eigen::VectorXd& x0, const Point& at_x0, Eigen::MatrixXd* d_terms,
                         Eigen::MatrixXd* d_rows);

  std::int64_t analyses() const { return analyses_; }
  std::int64_t failed() const { return failed_; }
  const spec::Study& study() const { return study_; }
  const spec::StudyLayout& layout() const { return layout_; }
  Eigen::VectorXd lower() const;
  Eigen::VectorXd upper() const;
  Eigen::VectorXd initial() const;

 private:
  const spec::Study& study_;
  spec::StudyLayout layout_;
  slp::SlpOptions fd_options_;
  std::int64_t analyses_ = 0;
  std::int64_t failed_ = 0;
};

}  // namespace mbopt::compare
