// The Model Exchange loop of Simulate (simulation.h): CVODES integrates the FMU's
// continuous states between events, one step at a time, so that the FMU
// hears of every completed step and outputs are read at interpolated states.
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "worker/fmu/run_steps.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::fmu::internal {
namespace {


// What the CVODES callbacks need, through their user data.
struct Callbacks {
  ModelInstance* instance = nullptr;
  int num_states = 0;  // the FMU's; CVODES integrates one dummy state when 0
  int num_indicators = 0;
  std::string failure;
};

// An FMI status as a SUNDIALS callback's answer: a discard asks for a
// smaller step (the FMU could not evaluate there), worse stops the run.
int CallbackCode(Callbacks* callbacks, CallStatus status, Call call, double t) {
  if (Succeeded(status)) return 0;
  if (status == CallStatus::kDiscard) return 1;
  callbacks->failure = callbacks->instance->Failure(call, status, t);
  return -1;
}

int SetTimeAndStates(Callbacks* callbacks, double t, const double* y) {
  ModelInstance& instance = *callbacks->instance;
  if (int code = CallbackCode(callbacks, instance.SetTime(t), Call::kSetTime, t); code != 0) return code;
  if (callbacks->num_states == 0) return 0;
  return CallbackCode(callbacks, instance.SetContinuousStates(y, callbacks->num_states), Call::kSetContinuousStates, t);
}

int Derivatives(double t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* callbacks = static_cast<Callbacks*>(user_data);
  return sundials::GuardCallback(&callbacks->failure, "the FMU's derivatives", [&] {
    if (callbacks->num_states == 0) {
      N_VGetArrayPointer(ydot)[0] = 0.0;
      return 0;
    }
    if (int code = SetTimeAndStates(callbacks, t, N_VGetArrayPointer(y)); code != 0) return code;
    return CallbackCode(callbacks,
                        callbacks->instance->GetDerivatives(N_VGetArrayPointer(ydot), callbacks->num_states),
                        Call::kGetDerivatives, t);
  });
}

int EventIndicators(double t, N_Vector y, double* indicators, void* user_data) {
  auto* callbacks = static_cast<Callbacks*>(user_data);
  return sundials::GuardCallback(&callbacks->failure, "the FMU's event indicators", [&] {
    // Root functions have no recoverable errors: any failure stops the run.
    if (SetTimeAndStates(callbacks, t, N_VGetArrayPointer(y)) != 0) return -1;
    const CallStatus status = callbacks->instance->GetEventIndicators(indicators, callbacks->num_indicators);
    return CallbackCode(callbacks, status, Call::kGetEventIndicators, t) == 0 ? 0 : -1;
  });
}

// The FMU's discrete states iterated to a fixed point at one event (the
// FMU is in event mode). False (and `result` failed) on an error or when
// the iteration does not settle.
bool IterateEvent(ModelInstance& instance, const RunOptions& options, double t, DiscreteStateUpdate* info,
                  RunResult* result) {
  info->update_needed = true;
  info->terminate = false;
  for (int iteration = 0; info->update_needed; ++iteration) {
    if (iteration == options.max_event_iterations) {
      return Fail(result, RunOutcome::kModelError,
                  absl::StrCat("the FMU's discrete states did not settle in ", options.max_event_iterations, " ",
                               instance.FunctionName(Call::kUpdateDiscreteStates), " calls at the event at t = ", t,
                               " s"));
    }
    const CallStatus status = instance.UpdateDiscreteStates(info);
    if (!Succeeded(status)) {
      return Fail(result, RunOutcome::kModelError, instance.Failure(Call::kUpdateDiscreteStates, status, t));
    }
    if (info->terminate) break;
  }
  return true;
}

class ModelExchangeRun {
 public:
  ModelExchangeRun(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run)
      : fmu_(fmu), instance_(instance), options_(options), run_(run) {}

  RunResult Go();

 private:
  bool Check(CallStatus status, Call call, double t) {
    if (Succeeded(status)) return true;
    return Fail(&result_, RunOutcome::kModelError, instance_.Failure(call, status, t));
  }
  bool CheckCvodes(int flag, const char* call) {
    if (flag >= 0) return true;
    return Fail(&result_, RunOutcome::kIntegratorFailure,
                absl::StrCat(call, " failed (flag ", flag, "): ", cvodes_message_));
  }
  bool Terminated(double t) {
    return Fail(&result_, RunOutcome::kTerminated,
                absl::StrCat("the FMU ended the simulation at t = ", t, " s, before the last output time (",
                             run_.stop_time_s, " s)",
                             instance_.RecentMessages().empty() ? ""
                                                                : absl::StrCat(" (FMU: ", instance_.RecentMessages(), ")")));
  }
  bool SetUpCvodes(double t0);
  bool ReadStates(double t);
  // Outputs at every output time up to `t_reached`, from CVODES'
  // interpolation over the last step.
  bool OutputsUpTo(double t_reached);
  bool HandleEvent(double t);

  const Fmu& fmu_;
  ModelInstance& instance_;
  const RunOptions& options_;
  const CheckedRun& run_;
  RunResult result_;
  DiscreteStateUpdate info_;
  Callbacks callbacks_;
  std::string cvodes_message_;
  std::size_t next_output_ = 0;
  int events_ = 0;

  // Declared in creation order: destroyed in reverse, CVODES memory first.
  sundials::Context context_;
  sundials::Vector y_;
  sundials::Vector y_interpolated_;
  sundials::Matrix matrix_;
  sundials::LinearSolver linear_solver_;
  sundials::Memory<CVodeFree> cvode_;
};

bool ModelExchangeRun::ReadStates(double t) {
  if (callbacks_.num_states == 0) {
    N_VGetArrayPointer(y_.get())[0] = 0.0;
    return true;
  }
  return Check(instance_.GetContinuousStates(N_VGetArrayPointer(y_.get()), callbacks_.num_states),
               Call::kGetContinuousStates, t);
}

bool ModelExchangeRun::SetUpCvodes(double t0) {
  const int n = std::max(callbacks_.num_states, 1);
  context_ = sundials::MakeContext();
  if (!context_) return Fail(&result_, RunOutcome::kIntegratorFailure, "SUNContext_Create failed");
  y_.reset(N_VNew_Serial(n, context_.get()));
  y_interpolated_.reset(N_VNew_Serial(n, context_.get()));
  matrix_.reset(SUNDenseMatrix(n, n, context_.get()));
  if (!y_ || !y_interpolated_ || !matrix_) return Fail(&result_, RunOutcome::kIntegratorFailure, "out of memory");
  linear_solver_.reset(SUNLinSol_Dense(y_.get(), matrix_.get(), context_.get()));
  cvode_.reset(CVodeCreate(CV_BDF, context_.get()));
  if (!linear_solver_ || !cvode_) return Fail(&result_, RunOutcome::kIntegratorFailure, "out of memory");
  void* mem = cvode_.get();
  if (!ReadStates(t0)) return false;
  return CheckCvodes(CVodeSetErrHandlerFn(mem, sundials::CaptureMessage, &cvodes_message_), "CVodeSetErrHandlerFn") &&
         CheckCvodes(CVodeInit(mem, Derivatives, t0, y_.get()), "CVodeInit") &&
         CheckCvodes(CVodeSetUserData(mem, &callbacks_), "CVodeSetUserData") &&
         CheckCvodes(CVodeSStolerances(mem, options_.relative_tolerance, options_.absolute_tolerance),
                     "CVodeSStolerances") &&
         CheckCvodes(CVodeSetLinearSolver(mem, linear_solver_.get(), matrix_.get()), "CVodeSetLinearSolver") &&
         CheckCvodes(CVodeSetMaxNumSteps(mem, static_cast<long>(options_.max_steps)), "CVodeSetMaxNumSteps") &&
         (callbacks_.num_indicators == 0 ||
          CheckCvodes(CVodeRootInit(mem, callbacks_.num_indicators, EventIndicators), "CVodeRootInit"));
}

bool ModelExchangeRun::OutputsUpTo(double t_reached) {
  const std::vector<double>& times = options_.output_times_s;
  while (next_output_ < times.size() && times[next_output_] <= t_reached) {
    const double t = times[next_output_];
    N_Vector y = y_.get();
    if (t < t_reached) {
      if (!CheckCvodes(CVodeGetDky(cvode_.get(), t, 0, y_interpolated_.get()), "CVodeGetDky")) return false;
      y = y_interpolated_.get();
    }
    if (SetTimeAndStates(&callbacks_, t, N_VGetArrayPointer(y)) != 0) {
      return Fail(&result_, RunOutcome::kModelError, callbacks_.failure);
    }
    if (!ReadOutputs(instance_, run_, static_cast<int>(next_output_), t, &result_)) return false;
    ++next_output_;
  }
  return true;
}

bool ModelExchangeRun::HandleEvent(double t) {
  if (++events_ > options_.max_events) {
    return Fail(&result_, RunOutcome::kIntegratorFailure,
                absl::StrCat("more than ", options_.max_events, " events by t = ", t,
                             " s (events chattering, or max_events too small)"));
  }
  if (!Check(instance_.EnterEventMode(), Call::kEnterEventMode, t)) return false;
  if (!IterateEvent(instance_, options_, t, &info_, &result_)) return false;
  if (info_.terminate) return Terminated(t);
  if (!Check(instance_.EnterContinuousTimeMode(), Call::kEnterContinuousTimeMode, t)) return false;
  // The states may have jumped: CVODES restarts from the FMU's states.
  if (!ReadStates(t)) return false;
  return CheckCvodes(CVodeReInit(cvode_.get(), t, y_.get()), "CVodeReInit");
}

RunResult ModelExchangeRun::Go() {
  result_.values.assign(run_.output_references.size(), std::vector<double>(options_.output_times_s.size()));
  const ModelDescription& description = fmu_.description();
  callbacks_.instance = &instance_;
  callbacks_.num_states = static_cast<int>(description.state_indices.size());
  callbacks_.num_indicators = description.number_of_event_indicators;
  const double t0 = options_.start_time_s;
  const double t_end = run_.stop_time_s;

  if (!Initialize(instance_, options_, run_, options_.relative_tolerance, &result_)) return result_;
  // Initialization is an event: discrete states settle before time runs.
  if (!IterateEvent(instance_, options_, t0, &info_, &result_)) return result_;
  if (info_.terminate) {
    Terminated(t0);
    return result_;
  }
  if (!Check(instance_.EnterContinuousTimeMode(), Call::kEnterContinuousTimeMode, t0)) return result_;
  if (!SetUpCvodes(t0)) return result_;
  if (!OutputsUpTo(t0)) return result_;

  double t = t0;
  while (next_output_ < options_.output_times_s.size()) {
    if (!WithinBudget(options_, t, &result_)) return result_;
    const bool time_event_ahead = info_.next_event_time_defined && info_.next_event_time_s <= t_end;
    if (time_event_ahead && info_.next_event_time_s <= t) {
      Fail(&result_, RunOutcome::kModelError,
           absl::StrCat("the FMU asked for a time event at t = ", info_.next_event_time_s,
                        " s, not after the current time ", t, " s"));
      return result_;
    }
    const double t_stop = time_event_ahead ? info_.next_event_time_s : t_end;
    if (!CheckCvodes(CVodeSetStopTime(cvode_.get(), t_stop), "CVodeSetStopTime")) return result_;
    const int flag = CVode(cvode_.get(), t_stop, y_.get(), &t, CV_ONE_STEP);
    if (flag < 0) {
      Fail(&result_, RunOutcome::kIntegratorFailure,
           absl::StrCat("CVODES failed at t = ", t, " s (flag ", flag, "): ",
                        callbacks_.failure.empty() ? cvodes_message_ : callbacks_.failure));
      return result_;
    }
    ++result_.integrator_steps;
    if (flag == CV_TSTOP_RETURN) t = t_stop;
    if (!OutputsUpTo(t)) return result_;
    if (next_output_ == options_.output_times_s.size()) break;

    // The FMU's state is wherever CVODES last evaluated it: back to the step's end.
    if (SetTimeAndStates(&callbacks_, t, N_VGetArrayPointer(y_.get())) != 0) {
      Fail(&result_, RunOutcome::kModelError, callbacks_.failure);
      return result_;
    }
    bool step_event = false;
    bool terminate = false;
    if (!Check(instance_.CompletedIntegratorStep(&step_event, &terminate), Call::kCompletedIntegratorStep, t)) {
      return result_;
    }
    if (terminate) {
      Terminated(t);
      return result_;
    }
    const bool state_event = flag == CV_ROOT_RETURN;
    const bool time_event = flag == CV_TSTOP_RETURN && time_event_ahead;
    if (state_event) result_.state_event_times_s.push_back(t);
    if (time_event) result_.time_event_times_s.push_back(t);
    if ((state_event || time_event || step_event) && !HandleEvent(t)) return result_;
  }
  instance_.Terminate();
  return result_;
}

}  // namespace

RunResult RunModelExchange(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run) {
  ModelExchangeRun me(fmu, instance, options, run);
  return me.Go();
}

}  // namespace mbopt::fmu::internal
