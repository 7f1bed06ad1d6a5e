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
  // Sensitivities: the knowns of the directional derivatives (the states,
  // then one parameter) and their seed (the state sensitivities, then 1).
  const SensitivityRun* sensitivities = nullptr;
  std::vector<ValueReference> knowns;
  std::vector<double> seed;
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

// d x' / d p_k = (d f / d x) s_k + d f / d p_k from one directional
// derivative per parameter: the states and p_k known, seeded with s_k and 1.
int SensitivityRhs(int count, double t, N_Vector y, N_Vector /*ydot*/, N_Vector* y_s, N_Vector* y_s_dot,
                   void* user_data, N_Vector /*tmp1*/, N_Vector /*tmp2*/) {
  auto* callbacks = static_cast<Callbacks*>(user_data);
  return sundials::GuardCallback(&callbacks->failure, "the FMU's directional derivatives", [&] {
    const int n = callbacks->num_states;
    if (n == 0) {  // CVODES' one dummy state has no sensitivity
      for (int k = 0; k < count; ++k) N_VConst(0.0, y_s_dot[k]);
      return 0;
    }
    if (int code = SetTimeAndStates(callbacks, t, N_VGetArrayPointer(y)); code != 0) return code;
    const SensitivityRun& run = *callbacks->sensitivities;
    for (int k = 0; k < count; ++k) {
      callbacks->knowns[n] = run.parameter_references[k];
      std::copy_n(N_VGetArrayPointer(y_s[k]), n, callbacks->seed.begin());
      callbacks->seed[n] = 1.0;
      const CallStatus status = callbacks->instance->GetDirectionalDerivative(
          run.derivative_references.data(), n, callbacks->knowns.data(), n + 1, callbacks->seed.data(),
          N_VGetArrayPointer(y_s_dot[k]));
      if (int code = CallbackCode(callbacks, status, Call::kGetDirectionalDerivative, t); code != 0) return code;
    }
    return 0;
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
  ModelExchangeRun(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run,
                   SensitivityRun* sensitivities)
      : fmu_(fmu), instance_(instance), options_(options), run_(run), sensitivities_(sensitivities) {}

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
  // Sensitivities: the states' at t0 (in initialization mode), CVODES' set
  // up, the outputs' at one output time, and giving them up with a reason
  // while the run goes on.
  bool InitialSensitivities(double t0);
  bool SetUpSensitivities();
  void OutputDerivatives(int time_index, double t);
  void DropSensitivities(std::string reason);
  bool sensitivities_on() const { return sensitivities_ != nullptr && sensitivities_->unavailable.empty(); }

  const Fmu& fmu_;
  ModelInstance& instance_;
  const RunOptions& options_;
  const CheckedRun& run_;
  SensitivityRun* sensitivities_;
  std::vector<std::vector<double>> initial_sensitivities_;  // [k][state]
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
  sundials::VectorArray y_s_;
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
          CheckCvodes(CVodeRootInit(mem, callbacks_.num_indicators, EventIndicators), "CVodeRootInit")) &&
         SetUpSensitivities();
}

bool ModelExchangeRun::InitialSensitivities(double t0) {
  // d x(t0) / d p_k: the states are initial unknowns, the parameter known.
  const SensitivityRun& run = *sensitivities_;
  const int n = callbacks_.num_states;
  initial_sensitivities_.assign(run.parameter_references.size(), std::vector<double>(n, 0.0));
  for (std::size_t k = 0; k < run.parameter_references.size() && n > 0; ++k) {
    const double one = 1.0;
    const CallStatus status = instance_.GetDirectionalDerivative(run.state_references.data(), n,
                                                                 &run.parameter_references[k], 1, &one,
                                                                 initial_sensitivities_[k].data());
    if (!Succeeded(status)) {
      DropSensitivities(absl::StrCat("the initial states' derivatives: ",
                                     instance_.Failure(Call::kGetDirectionalDerivative, status, t0)));
      return true;
    }
  }
  return true;
}

bool ModelExchangeRun::SetUpSensitivities() {
  if (!sensitivities_on()) return true;
  const int count = static_cast<int>(sensitivities_->parameter_references.size());
  const int n = callbacks_.num_states;
  y_s_ = sundials::VectorArray(N_VCloneVectorArray(count, y_.get()), count);
  if (!y_s_) return Fail(&result_, RunOutcome::kIntegratorFailure, "out of memory");
  for (int k = 0; k < count; ++k) {
    N_VConst(0.0, y_s_[k]);
    std::copy_n(initial_sensitivities_[k].begin(), n, N_VGetArrayPointer(y_s_[k]));
  }
  callbacks_.sensitivities = sensitivities_;
  callbacks_.knowns = sensitivities_->state_references;
  callbacks_.knowns.push_back(0);
  callbacks_.seed.assign(n + 1, 0.0);
  void* mem = cvode_.get();
  // Staggered: the states' Newton iteration is left as without
  // sensitivities; the sensitivities are in the error test.
  return CheckCvodes(CVodeSensInit(mem, count, CV_STAGGERED, SensitivityRhs, y_s_.get()), "CVodeSensInit") &&
         CheckCvodes(CVodeSensEEtolerances(mem), "CVodeSensEEtolerances") &&
         CheckCvodes(CVodeSetSensErrCon(mem, SUNTRUE), "CVodeSetSensErrCon");
}

void ModelExchangeRun::DropSensitivities(std::string reason) {
  if (!sensitivities_on()) return;
  sensitivities_->unavailable = std::move(reason);
  sensitivities_->output_derivatives.clear();
  if (cvode_) CVodeSensToggleOff(cvode_.get());
}

void ModelExchangeRun::OutputDerivatives(int time_index, double t) {
  if (!sensitivities_on()) return;
  SensitivityRun& run = *sensitivities_;
  const int count = static_cast<int>(run.parameter_references.size());
  const int n = callbacks_.num_states;
  // CVODES' interpolation of the sensitivities, as of the states; before
  // the first step there is nothing to interpolate (and CVODES would
  // divide by its zero step), so the initial sensitivities.
  const int flag = result_.integrator_steps == 0 ? 0 : CVodeGetSensDky(cvode_.get(), t, 0, y_s_.get());
  if (flag < 0) {
    DropSensitivities(absl::StrCat("CVodeGetSensDky failed at t = ", t, " s (flag ", flag, ")"));
    return;
  }
  for (int k = 0; k < count; ++k) {
    const double* s = N_VGetArrayPointer(y_s_[k]);
    callbacks_.knowns[n] = run.parameter_references[k];
    std::copy_n(s, n, callbacks_.seed.begin());
    callbacks_.seed[n] = 1.0;
    for (std::size_t o = 0; o < run.output_state_index.size(); ++o) {
      double derivative = 0.0;
      if (run.output_state_index[o] >= 0) {
        derivative = s[run.output_state_index[o]];
      } else {
        const CallStatus status = instance_.GetDirectionalDerivative(
            &run_.output_references[o], 1, callbacks_.knowns.data(), n + 1, callbacks_.seed.data(), &derivative);
        if (!Succeeded(status)) {
          DropSensitivities(absl::StrCat("output ", o + 1, "'s derivative: ",
                                         instance_.Failure(Call::kGetDirectionalDerivative, status, t)));
          return;
        }
      }
      run.output_derivatives[k][o][time_index] = derivative;
    }
  }
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
    OutputDerivatives(static_cast<int>(next_output_), t);
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
  // The sensitivities jump at an event in a way the FMU does not tell.
  DropSensitivities(absl::StrCat("an event at t = ", t, " s: sensitivities across events are not computed"));
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

  if (sensitivities_ != nullptr) {
    sensitivities_->output_derivatives.assign(
        sensitivities_->parameter_references.size(),
        std::vector<std::vector<double>>(run_.output_references.size(),
                                         std::vector<double>(options_.output_times_s.size(), 0.0)));
  }
  const std::function<bool()> in_initialization =
      sensitivities_ == nullptr ? std::function<bool()>() : [this, t0] { return InitialSensitivities(t0); };
  if (!Initialize(instance_, options_, run_, options_.relative_tolerance, &result_, in_initialization)) {
    return result_;
  }
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

RunResult RunModelExchange(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run,
                           SensitivityRun* sensitivities) {
  ModelExchangeRun me(fmu, instance, options, run, sensitivities);
  return me.Go();
}

}  // namespace mbopt::fmu::internal
