#include "spec/analysis_outcome.h"

#include "spec/analysis_report.h"

#include <array>
#include <utility>

namespace mbopt::spec {
namespace {

constexpr std::array<std::pair<FailureKind, const char*>, 11> kNames = {{
    {FailureKind::kNone, "ok"},
    {FailureKind::kInvalidModel, "invalid_model"},
    {FailureKind::kAssembly, "assembly"},
    {FailureKind::kIntegrator, "integrator"},
    {FailureKind::kTimeLimit, "time_limit"},
    {FailureKind::kNonFiniteValue, "non_finite_value"},
    {FailureKind::kModelValidity, "model_validity"},
    {FailureKind::kService, "service"},
    {FailureKind::kInjected, "injected"},
    {FailureKind::kCancelled, "cancelled"},
    {FailureKind::kUnclassified, "unclassified"},
}};

}  // namespace

const char* FailureKindName(FailureKind kind) {
  for (const auto& [k, name] : kNames) {
    if (k == kind) return name;
  }
  return "unclassified";
}

std::optional<FailureKind> ParseFailureKind(std::string_view name) {
  for (const auto& [k, n] : kNames) {
    if (name == n) return k;
  }
  return std::nullopt;
}

const char* FormulationName(Formulation f) {
  switch (f) {
    case Formulation::kKinematic:
      return "kinematic";
    case Formulation::kKinetostatic:
      return "kinetostatic";
    case Formulation::kDynamic:
      return "dynamic";
    case Formulation::kElastodynamic:
      return "elastodynamic";
    case Formulation::kStatic:
      return "static";
    case Formulation::kExternal:
      return "external";
  }
  return "unknown";
}

AnalysisCounters& AnalysisCounters::operator+=(const AnalysisCounters& other) {
  time_steps += other.time_steps;
  rhs_evaluations += other.rhs_evaluations;
  jacobian_evaluations += other.jacobian_evaluations;
  newton_iterations += other.newton_iterations;
  position_solves += other.position_solves;
  wall_seconds += other.wall_seconds;
  return *this;
}

}  // namespace mbopt::spec
