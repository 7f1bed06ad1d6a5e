#include "bench/compare/method_run.h"

#include <utility>

#include "common/status_macros.h"
#include "server/slp/finite_difference.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::compare {

CountedStudy::CountedStudy(const spec::Study& study, spec::StudyLayout layout,
                           slp::SlpOptions fd_options)
    : study_(study), layout_(std::move(layout)), fd_options_(fd_options) {
  fd_options_.finite_difference = slp::FiniteDifferenceScheme::kForward;
}

Eigen::VectorXd CountedStudy::lower() const {
  Eigen::VectorXd v(study_.variables.size());
  for (size_t i = 0; i < study_.variables.size(); ++i) v[i] = study_.variables[i].lower;
  return v;
}
Eigen::VectorXd CountedStudy::upper() const {
  Eigen::VectorXd v(study_.variables.size());
  for (size_t i = 0; i < study_.variables.size(); ++i) v[i] = study_.variables[i].upper;
  return v;
}
Eigen::VectorXd CountedStudy::initial() const {
  Eigen::VectorXd v(study_.variables.size());
  for (size_t i = 0; i < study_.variables.size(); ++i) v[i] = study_.variables[i].initial;
  return v;
}

absl::StatusOr<CountedStudy::Point> CountedStudy::Evaluate(const Eigen::VectorXd& x) {
  MBOPT_ASSIGN_OR_RETURN(engine::StudyEvaluation e, local_run::EvaluateDesign(study_, layout_, x));
  ++analyses_;
  Point p;
  if (!e.ok()) {
    ++failed_;
    p.failure_reason = e.failure.reason;
    return p;
  }
  const spec::StudyValues& v = *e.values;
  p.ok = true;
  p.terms = Eigen::Map<const Eigen::VectorXd>(v.objective_terms.data(),
                                              static_cast<Eigen::Index>(v.objective_terms.size()));
  p.normalized.resize(layout_.num_constraints());
  for (int h = 0; h < layout_.num_constraints(); ++h) {
    const spec::ConstraintRow& row = layout_.rows[h];
    p.normalized[h] = (v.constraint_values[h] - row.limit_si) / row.scale;
  }
  p.objective = v.objective;
  p.max_violation = v.max_violation;
  return p;
}

absl::Status CountedStudy::Jacobians(const Eigen::VectorXd& x0, const Point& at_x0,
                                     Eigen::MatrixXd* d_terms, Eigen::MatrixXd* d_rows) {
  const Eigen::Index n = x0.size();
  d_terms->setZero(at_x0.terms.size(), n);
  d_rows->setZero(at_x0.normalized.size(), n);
  const Eigen::VectorXd lo = lower();
  const Eigen::VectorXd hi = upper();
  for (Eigen::Index i = 0; i < n; ++i) {
    double step = slp::PlanSteps(x0[i], lo[i], hi[i], fd_options_).front();
    for (int attempt = 0; attempt < 2; ++attempt) {
      Eigen::VectorXd x = x0;
      x[i] += step;
      MBOPT_ASSIGN_OR_RETURN(Point p, Evaluate(x));
      if (p.ok) {
        d_terms->col(i) = (p.terms - at_x0.terms) / step;
        d_rows->col(i) = (p.normalized - at_x0.normalized) / step;
        break;
      }
      step = slp::RetryStep(x0[i], lo[i], hi[i], step);
    }
  }
  return absl::OkStatus();
}

}  // namespace mbopt::compare
