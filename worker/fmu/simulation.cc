#include "worker/fmu/simulation.h"

#include <cmath>
#include <set>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "worker/fmu/run_steps.h"

namespace mbopt::fmu {
namespace {

using internal::CheckedRun;
using internal::Fail;

// How far an output time may be from a whole number of communication steps,
// in steps: output times written in decimal (0.1 s with a 0.01 s step) are
// not exact multiples in binary.
constexpr double kGridAlignmentSteps = 1e-9;

bool IsSettableParameter(const ScalarVariable& variable) {
  return variable.type == VariableType::kReal && variable.causality == Causality::kParameter &&
         (variable.variability == Variability::kFixed || variable.variability == Variability::kTunable);
}

std::string NamesOf(const ModelDescription& description, bool (*keep)(const ScalarVariable&)) {
  std::vector<std::string> names;
  for (const ScalarVariable& variable : description.variables) {
    if (keep(variable)) names.push_back(variable.name);
  }
  return names.empty() ? "none" : absl::StrJoin(names, ", ");
}

absl::StatusOr<double> CommunicationStep(const Fmu& fmu, const RunOptions& options) {
  const std::optional<double> step =
      options.communication_step_s ? options.communication_step_s : fmu.description().default_experiment.step_size_s;
  if (!step.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat(
        fmu.archive_path().string(), ": no communication step: the model description's <DefaultExperiment> has no "
        "stepSize and the run gives none"));
  }
  if (!(*step > 0.0) || !std::isfinite(*step)) {
    return absl::InvalidArgumentError(absl::StrCat("communication step ", *step, " s; expected a step > 0 s"));
  }
  for (std::size_t i = 0; i < options.output_times_s.size(); ++i) {
    const double steps = (options.output_times_s[i] - options.start_time_s) / *step;
    if (std::abs(steps - std::round(steps)) > kGridAlignmentSteps * std::max(1.0, steps)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "output time ", i, " (", options.output_times_s[i], " s) is not a whole number of communication steps (",
          *step, " s) after the start time (", options.start_time_s,
          " s); a co-simulation FMU is sampled only at its communication points"));
    }
  }
  return *step;
}

RunResult RunCoSimulation(ModelInstance& instance, const RunOptions& options, const CheckedRun& run, double step_s) {
  RunResult result;
  result.values.assign(run.output_references.size(), std::vector<double>(options.output_times_s.size()));
  const double tolerance = options.relative_tolerance;
  if (!internal::Initialize(instance, options, run, tolerance, &result)) return result;
  // Communication points are start + m * step, computed from m each time so
  // that no rounding accumulates over many steps.
  std::int64_t m = 0;
  for (std::size_t i = 0; i < options.output_times_s.size(); ++i) {
    const auto target = static_cast<std::int64_t>(std::llround((options.output_times_s[i] - options.start_time_s) / step_s));
    for (; m < target; ++m) {
      const double point = options.start_time_s + static_cast<double>(m) * step_s;
      bool terminate = false;
      const CallStatus status = instance.DoStep(point, step_s, &terminate);
      ++result.integrator_steps;
      if (!Succeeded(status)) {
        Fail(&result, RunOutcome::kModelError, instance.Failure(Call::kDoStep, status, point));
        return result;
      }
      if (terminate) {
        const std::string messages = instance.RecentMessages();
        Fail(&result, RunOutcome::kTerminated,
             absl::StrCat("the FMU ended the simulation at t = ", point + step_s, " s, before the last output time (",
                          run.stop_time_s, " s)", messages.empty() ? "" : absl::StrCat(" (FMU: ", messages, ")")));
        return result;
      }
      if (!internal::WithinBudget(options, point + step_s, &result)) return result;
    }
    if (!internal::ReadOutputs(instance, run, static_cast<int>(i), options.output_times_s[i], &result)) return result;
  }
  instance.Terminate();
  return result;
}

}  // namespace

const char* RunOutcomeName(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::kOk: return "ok";
    case RunOutcome::kModelError: return "model error";
    case RunOutcome::kIntegratorFailure: return "integrator failure";
    case RunOutcome::kTerminated: return "terminated by the FMU";
    case RunOutcome::kTimeLimit: return "time limit";
    case RunOutcome::kCancelled: return "cancelled";
  }
  return "?";
}

namespace internal {

absl::StatusOr<CheckedRun> CheckRequest(const Fmu& fmu, const RunOptions& options) {
  const ModelDescription& description = fmu.description();
  const std::string where = fmu.archive_path().string();
  CheckedRun run;
  std::set<std::string> seen;
  for (const auto& [name, value] : options.parameters) {
    const ScalarVariable* variable = description.Find(name);
    if (variable == nullptr || !IsSettableParameter(*variable)) {
      const std::string what =
          variable == nullptr
              ? "has no variable"
              : absl::StrCat("has a variable (causality ", CausalityName(variable->causality),
                             ") that is not a Real parameter of variability fixed or tunable,");
      return absl::InvalidArgumentError(absl::StrCat(where, " ", what, " named \"", name,
                                                     "\"; its Real parameters are: ",
                                                     NamesOf(description, IsSettableParameter)));
    }
    if (!seen.insert(name).second) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": parameter \"", name, "\" is set twice"));
    }
    if (!std::isfinite(value)) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": parameter \"", name, "\" set to ", value,
                                                     "; expected a finite value"));
    }
    run.parameter_references.push_back(variable->value_reference);
    run.parameter_values.push_back(value);
  }
  for (const std::string& name : options.outputs) {
    const ScalarVariable* variable = description.Find(name);
    if (variable == nullptr || variable->type != VariableType::kReal) {
      return absl::InvalidArgumentError(absl::StrCat(
          where, variable == nullptr ? " has no variable" : " has a variable that is not Real", " named \"", name,
          "\" to output; its Real variables are: ",
          NamesOf(description, [](const ScalarVariable& v) { return v.type == VariableType::kReal; })));
    }
    run.output_references.push_back(variable->value_reference);
  }
  if (!std::isfinite(options.start_time_s)) {
    return absl::InvalidArgumentError(absl::StrCat("start time ", options.start_time_s, " s is not finite"));
  }
  if (options.output_times_s.empty()) return absl::InvalidArgumentError("no output times");
  double previous = options.start_time_s;
  for (std::size_t i = 0; i < options.output_times_s.size(); ++i) {
    const double t = options.output_times_s[i];
    if (!std::isfinite(t) || t < previous) {
      return absl::InvalidArgumentError(absl::StrCat("output time ", i, " (", t, " s) is before ",
                                                     i == 0 ? "the start time" : "the one before it", " (",
                                                     previous, " s) or not finite"));
    }
    previous = t;
  }
  run.stop_time_s = options.output_times_s.back();
  if (!(options.relative_tolerance > 0.0) || !(options.absolute_tolerance > 0.0) || options.max_steps <= 0 ||
      options.max_events < 0 || options.max_event_iterations <= 0) {
    return absl::InvalidArgumentError(
        "run options: tolerances must be > 0, max_steps and max_event_iterations > 0, max_events >= 0");
  }
  return run;
}

std::unique_ptr<ModelInstance> Instantiate(const Fmu& fmu, RunResult* result) {
  std::unique_ptr<ModelInstance> instance = fmu.Instantiate();
  if (instance->instantiated()) return instance;
  const std::string messages = instance->RecentMessages();
  const char* function = fmu.description().fmi_major_version >= 3
                             ? (fmu.interface() == Interface::kModelExchange ? "fmi3InstantiateModelExchange"
                                                                             : "fmi3InstantiateCoSimulation")
                             : "fmi2Instantiate";
  Fail(result, RunOutcome::kModelError,
       absl::StrCat(function, " refused to make an instance",
                    messages.empty() ? "" : absl::StrCat(" (FMU: ", messages, ")")));
  return nullptr;
}

bool WithinBudget(const RunOptions& options, double time_s, RunResult* result) {
  if (options.budget == nullptr) return true;
  spec::AnalysisFailure spent = options.budget->Check(time_s);
  if (spent.ok()) return true;
  return Fail(result, spent.kind == spec::FailureKind::kCancelled ? RunOutcome::kCancelled : RunOutcome::kTimeLimit,
              std::move(spent.reason));
}

bool Fail(RunResult* result, RunOutcome outcome, std::string reason) {
  result->outcome = outcome;
  result->reason = std::move(reason);
  return false;
}

bool Initialize(ModelInstance& instance, const RunOptions& options, const CheckedRun& run, double tolerance,
                RunResult* result, const std::function<bool()>& in_initialization_mode) {
  const double t0 = options.start_time_s;
  CallStatus status = instance.SetUpExperiment(tolerance, t0, run.stop_time_s);
  if (!Succeeded(status)) {
    return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kSetUpExperiment, status, t0));
  }
  if (!run.parameter_references.empty()) {
    status = instance.SetFloat64(run.parameter_references.data(), run.parameter_references.size(),
                                 run.parameter_values.data());
    if (!Succeeded(status)) {
      return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kSetFloat64, status, t0, "parameters"));
    }
  }
  status = instance.EnterInitializationMode();
  if (!Succeeded(status)) {
    return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kEnterInitializationMode, status, t0));
  }
  if (in_initialization_mode && !in_initialization_mode()) return false;
  status = instance.ExitInitializationMode();
  if (!Succeeded(status)) {
    return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kExitInitializationMode, status, t0));
  }
  return true;
}

bool ReadOutputs(ModelInstance& instance, const CheckedRun& run, int time_index, double time_s, RunResult* result) {
  if (run.output_references.empty()) return true;
  std::vector<double> values(run.output_references.size());
  const CallStatus status = instance.GetFloat64(run.output_references.data(), values.size(), values.data());
  if (!Succeeded(status)) {
    return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kGetFloat64, status, time_s, "outputs"));
  }
  for (std::size_t k = 0; k < values.size(); ++k) result->values[k][time_index] = values[k];
  return true;
}

}  // namespace internal

absl::StatusOr<RunResult> Simulate(const Fmu& fmu, const RunOptions& options) {
  auto run = internal::CheckRequest(fmu, options);
  if (!run.ok()) return run.status();
  std::optional<double> step;
  if (fmu.interface() == Interface::kCoSimulation) {
    auto checked_step = CommunicationStep(fmu, options);
    if (!checked_step.ok()) return checked_step.status();
    step = *checked_step;
  }
  RunResult result;
  std::unique_ptr<ModelInstance> instance = internal::Instantiate(fmu, &result);
  if (instance == nullptr) return result;
  if (step.has_value()) return RunCoSimulation(*instance, options, *run, *step);
  return internal::RunModelExchange(fmu, *instance, options, *run);
}

}  // namespace mbopt::fmu
