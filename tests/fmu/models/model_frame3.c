/* The FMI 3.0 functions of the test models, over the same model.h interface
 * as model_frame.c's FMI 2.0 ones, so that one model file makes an FMU of
 * either version. Co-simulation integrates with classical Runge-Kutta at a
 * fixed substep, stopping exactly at time events (model_frame.c's scheme). */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/fmu/models/model.h"
#include "worker/fmu/fmi3_api.h"

#define EXPORT __attribute__((visibility("default")))

/* The model and the importer's logger; the model comes first so that a
 * Model* is the instance's address. */
typedef struct {
  Model model;
  fmi3InstanceEnvironment environment;
  fmi3LogMessageCallback log_message;
} Instance;

void ModelLog(const Model* m, fmi2Status status, const char* message, double value) {
  const Instance* instance = (const Instance*)m;
  if (instance->log_message == NULL) return;
  char text[256];
  snprintf(text, sizeof text, message, value);
  instance->log_message(instance->environment, (fmi3Status)status, "model", text);
}

static fmi3Instance Instantiate(fmi3String instance_name, fmi3String token, fmi2Type type,
                                fmi3InstanceEnvironment environment, fmi3LogMessageCallback log_message) {
  if (token == NULL || strcmp(token, kModelGuid) != 0) {
    if (log_message != NULL) log_message(environment, fmi3Error, "model", "wrong instantiation token");
    return NULL;
  }
  Instance* instance = (Instance*)calloc(1, sizeof(Instance));
  if (instance == NULL) return NULL;
  instance->environment = environment;
  instance->log_message = log_message;
  instance->model.type = type;
  strncpy(instance->model.instance_name, instance_name != NULL ? instance_name : "",
          sizeof instance->model.instance_name - 1);
  ModelSetStartValues(&instance->model);
  return instance;
}

EXPORT const char* fmi3GetVersion(void) { return "3.0"; }

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String instance_name, fmi3String token, fmi3String resource_path,
                                                 fmi3Boolean visible, fmi3Boolean logging_on,
                                                 fmi3InstanceEnvironment environment,
                                                 fmi3LogMessageCallback log_message) {
  (void)resource_path;
  (void)visible;
  (void)logging_on;
  return Instantiate(instance_name, token, fmi2ModelExchange, environment, log_message);
}

EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String instance_name, fmi3String token, fmi3String resource_path,
                                                fmi3Boolean visible, fmi3Boolean logging_on,
                                                fmi3Boolean event_mode_used, fmi3Boolean early_return_allowed,
                                                const fmi3ValueReference required[], size_t n_required,
                                                fmi3InstanceEnvironment environment,
                                                fmi3LogMessageCallback log_message,
                                                fmi3IntermediateUpdateCallback intermediate_update) {
  (void)resource_path;
  (void)visible;
  (void)logging_on;
  (void)required;
  (void)n_required;
  (void)intermediate_update;
  if (event_mode_used || early_return_allowed) {
    if (log_message != NULL) log_message(environment, fmi3Error, "model", "no event mode, no early return");
    return NULL;
  }
  return Instantiate(instance_name, token, fmi2CoSimulation, environment, log_message);
}

EXPORT void fmi3FreeInstance(fmi3Instance instance) { free(instance); }

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                              fmi3Float64 tolerance, fmi3Float64 start_time,
                                              fmi3Boolean stop_time_defined, fmi3Float64 stop_time) {
  (void)tolerance_defined;
  (void)tolerance;
  (void)stop_time_defined;
  (void)stop_time;
  ((Model*)instance)->time = start_time;
  return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  return (fmi3Status)ModelInitialize((Model*)instance);
}

EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
  (void)instance;
  return fmi3OK;
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance instance) {
  (void)instance;
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                 fmi3Float64 values[], size_t n_values) {
  Model* m = (Model*)instance;
  if (n_values != nvr) return fmi3Error;
  ModelEvaluate(m);
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] >= (fmi3ValueReference)kModelNumReals) {
      ModelLog(m, fmi2Error, "no Float64 variable has value reference %g", (double)vr[i]);
      return fmi3Error;
    }
    values[i] = m->r[vr[i]];
  }
  return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                 const fmi3Float64 values[], size_t n_values) {
  Model* m = (Model*)instance;
  if (n_values != nvr) return fmi3Error;
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] >= (fmi3ValueReference)kModelNumReals) {
      ModelLog(m, fmi2Error, "no Float64 variable has value reference %g", (double)vr[i]);
      return fmi3Error;
    }
    m->r[vr[i]] = values[i];
  }
  return fmi3OK;
}

EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean* update_needed,
                                           fmi3Boolean* terminate, fmi3Boolean* nominals_changed,
                                           fmi3Boolean* values_changed, fmi3Boolean* next_event_time_defined,
                                           fmi3Float64* next_event_time) {
  Model* m = (Model*)instance;
  const fmi2Boolean changed = ModelEvent(m);
  *update_needed = fmi3False;
  *terminate = m->terminate ? fmi3True : fmi3False;
  *nominals_changed = fmi3False;
  *values_changed = changed ? fmi3True : fmi3False;
  *next_event_time_defined = m->next_event_time_defined ? fmi3True : fmi3False;
  *next_event_time = m->next_event_time;
  return fmi3OK;
}

EXPORT fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
  (void)instance;
  return fmi3OK;
}

EXPORT fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean no_set_prior,
                                              fmi3Boolean* enter_event_mode, fmi3Boolean* terminate) {
  (void)no_set_prior;
  *enter_event_mode = fmi3False;
  *terminate = ((Model*)instance)->terminate ? fmi3True : fmi3False;
  return fmi3OK;
}

EXPORT fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
  ((Model*)instance)->time = time;
  return fmi3OK;
}

EXPORT fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t nx) {
  Model* m = (Model*)instance;
  if (nx != (size_t)kModelNumStates) return fmi3Error;
  for (size_t i = 0; i < nx; ++i) m->r[kModelStates[i]] = x[i];
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t nx) {
  Model* m = (Model*)instance;
  if (nx != (size_t)kModelNumStates) return fmi3Error;
  for (size_t i = 0; i < nx; ++i) x[i] = m->r[kModelStates[i]];
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nx) {
  Model* m = (Model*)instance;
  if (nx != (size_t)kModelNumStates) return fmi3Error;
  ModelEvaluate(m);
  for (size_t i = 0; i < nx; ++i) derivatives[i] = m->r[kModelDerivatives[i]];
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 indicators[], size_t ni) {
  if (ni != (size_t)kModelNumEventIndicators) return fmi3Error;
  ModelEventIndicators((Model*)instance, indicators);
  return fmi3OK;
}

/* sensitivity = (d unknowns / d knowns) seed, from the model's partials. */
static int DirectionalDerivative(Model* m, const unsigned int unknowns[], size_t n_unknowns,
                                 const unsigned int knowns[], size_t n_knowns, const double seed[],
                                 double sensitivity[]) {
  ModelEvaluate(m);
  for (size_t i = 0; i < n_unknowns; ++i) {
    sensitivity[i] = 0.0;
    for (size_t j = 0; j < n_knowns; ++j) {
      double partial = 0.0;
      if (ModelPartialDerivative(m, unknowns[i], knowns[j], &partial) != fmi2OK) return 0;
      sensitivity[i] += partial * seed[j];
    }
  }
  return 1;
}

EXPORT fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                               size_t n_unknowns, const fmi3ValueReference knowns[], size_t n_knowns,
                                               const fmi3Float64 seed[], size_t n_seed, fmi3Float64 sensitivity[],
                                               size_t n_sensitivity) {
  if (n_seed != n_knowns || n_sensitivity != n_unknowns) return fmi3Error;
  return DirectionalDerivative((Model*)instance, unknowns, n_unknowns, knowns, n_knowns, seed, sensitivity)
             ? fmi3OK
             : fmi3Error;
}

/* One classical Runge-Kutta step of length h from m->time. */
static void RungeKuttaStep(Model* m, fmi3Float64 h) {
  fmi3Float64 x0[MODEL_MAX_REALS], k[4][MODEL_MAX_REALS];
  const int n = kModelNumStates;
  const fmi3Float64 t0 = m->time;
  const fmi3Float64 stage[4] = {0.0, 0.5 * h, 0.5 * h, h};
  for (int i = 0; i < n; ++i) x0[i] = m->r[kModelStates[i]];
  for (int s = 0; s < 4; ++s) {
    m->time = t0 + stage[s];
    for (int i = 0; i < n; ++i) m->r[kModelStates[i]] = x0[i] + (s == 0 ? 0.0 : stage[s] * k[s - 1][i]);
    ModelEvaluate(m);
    for (int i = 0; i < n; ++i) k[s][i] = m->r[kModelDerivatives[i]];
  }
  for (int i = 0; i < n; ++i) {
    m->r[kModelStates[i]] = x0[i] + h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
  }
  m->time = t0 + h;
  ModelEvaluate(m);
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 point, fmi3Float64 step, fmi3Boolean no_set_prior,
                             fmi3Boolean* event_handling_needed, fmi3Boolean* terminate, fmi3Boolean* early_return,
                             fmi3Float64* last_successful_time) {
  (void)no_set_prior;
  Model* m = (Model*)instance;
  m->time = point;
  for (int j = 1; j <= kModelSubstepsPerStep; ++j) {
    const fmi3Float64 target = j == kModelSubstepsPerStep ? point + step : point + step * j / kModelSubstepsPerStep;
    while (m->next_event_time_defined && m->next_event_time > m->time && m->next_event_time <= target) {
      RungeKuttaStep(m, m->next_event_time - m->time);
      m->time = m->next_event_time;
      ModelEvent(m);
    }
    if (target > m->time) RungeKuttaStep(m, target - m->time);
    m->time = target;
  }
  *event_handling_needed = fmi3False;
  *terminate = m->terminate ? fmi3True : fmi3False;
  *early_return = fmi3False;
  *last_successful_time = m->time;
  return fmi3OK;
}
