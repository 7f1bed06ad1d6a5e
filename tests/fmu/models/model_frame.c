/* The FMI 2.0 functions of the test models, over the model.h interface.
 * Co-simulation integrates with classical Runge-Kutta at a fixed substep,
 * stopping exactly at time events; state events are only detected at the
 * end of a substep (the test models offering co-simulation have none). */
#include <stdlib.h>
#include <string.h>

#include "tests/fmu/models/model.h"

#define EXPORT __attribute__((visibility("default")))

void ModelLog(const Model* m, fmi2Status status, const char* message, double value) {
  if (m->callbacks.logger != NULL) {
    m->callbacks.logger(m->callbacks.componentEnvironment, m->instance_name, status, "model", message, value);
  }
}

EXPORT const char* fmi2GetVersion(void) { return "2.0"; }
EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instance_name, fmi2Type type, fmi2String guid,
                                     fmi2String resource_location, const fmi2CallbackFunctions* callbacks,
                                     fmi2Boolean visible, fmi2Boolean logging_on) {
  (void)resource_location;
  (void)visible;
  (void)logging_on;
  if (callbacks == NULL || guid == NULL || strcmp(guid, kModelGuid) != 0) {
    if (callbacks != NULL && callbacks->logger != NULL) {
      callbacks->logger(callbacks->componentEnvironment, instance_name, fmi2Error, "model",
                        "wrong guid %s", guid != NULL ? guid : "(none)");
    }
    return NULL;
  }
  Model* m = (Model*)calloc(1, sizeof(Model));
  if (m == NULL) return NULL;
  m->callbacks = *callbacks;
  m->type = type;
  strncpy(m->instance_name, instance_name != NULL ? instance_name : "", sizeof m->instance_name - 1);
  ModelSetStartValues(m);
  return m;
}

EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start_time, fmi2Boolean stop_time_defined, fmi2Real stop_time) {
  (void)tolerance_defined;
  (void)tolerance;
  (void)stop_time_defined;
  (void)stop_time;
  ((Model*)c)->time = start_time;
  return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return ModelInitialize((Model*)c); }

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  Model* m = (Model*)c;
  ModelSetStartValues(m);
  m->time = 0.0;
  m->terminate = fmi2False;
  return fmi2OK;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
  Model* m = (Model*)c;
  ModelEvaluate(m);
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] >= (fmi2ValueReference)kModelNumReals) {
      ModelLog(m, fmi2Error, "no Real variable has value reference %g", (double)vr[i]);
      return fmi2Error;
    }
    value[i] = m->r[vr[i]];
  }
  return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
  Model* m = (Model*)c;
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] >= (fmi2ValueReference)kModelNumReals) {
      ModelLog(m, fmi2Error, "no Real variable has value reference %g", (double)vr[i]);
      return fmi2Error;
    }
    m->r[vr[i]] = value[i];
  }
  return fmi2OK;
}

EXPORT fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
  ((Model*)c)->time = time;
  return fmi2OK;
}

EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
  Model* m = (Model*)c;
  for (size_t i = 0; i < nx && i < (size_t)kModelNumStates; ++i) m->r[kModelStates[i]] = x[i];
  return fmi2OK;
}

EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
  Model* m = (Model*)c;
  for (size_t i = 0; i < nx && i < (size_t)kModelNumStates; ++i) x[i] = m->r[kModelStates[i]];
  return fmi2OK;
}

EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
  Model* m = (Model*)c;
  ModelEvaluate(m);
  for (size_t i = 0; i < nx && i < (size_t)kModelNumStates; ++i) derivatives[i] = m->r[kModelDerivatives[i]];
  return fmi2OK;
}

EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real indicators[], size_t ni) {
  if (ni != (size_t)kModelNumEventIndicators) return fmi2Error;
  ModelEventIndicators((Model*)c, indicators);
  return fmi2OK;
}

EXPORT fmi2Status fmi2EnterEventMode(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo* info) {
  Model* m = (Model*)c;
  const fmi2Boolean changed = ModelEvent(m);
  info->newDiscreteStatesNeeded = fmi2False;
  info->terminateSimulation = m->terminate;
  info->nominalsOfContinuousStatesChanged = fmi2False;
  info->valuesOfContinuousStatesChanged = changed;
  info->nextEventTimeDefined = m->next_event_time_defined;
  info->nextEventTime = m->next_event_time;
  return fmi2OK;
}

EXPORT fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

EXPORT fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean no_set_prior, fmi2Boolean* enter_event_mode,
                                              fmi2Boolean* terminate_simulation) {
  (void)no_set_prior;
  *enter_event_mode = fmi2False;
  *terminate_simulation = ((Model*)c)->terminate;
  return fmi2OK;
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

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknowns[], size_t n_unknowns,
                                               const fmi2ValueReference knowns[], size_t n_knowns,
                                               const fmi2Real seed[], fmi2Real sensitivity[]) {
  return DirectionalDerivative((Model*)c, unknowns, n_unknowns, knowns, n_knowns, seed, sensitivity) ? fmi2OK
                                                                                                      : fmi2Error;
}

/* One classical Runge-Kutta step of length h from m->time. */
static void RungeKuttaStep(Model* m, fmi2Real h) {
  fmi2Real x0[MODEL_MAX_REALS], k[4][MODEL_MAX_REALS];
  const int n = kModelNumStates;
  const fmi2Real t0 = m->time;
  const fmi2Real stage_time[4] = {0.0, 0.5 * h, 0.5 * h, h};
  const fmi2Real stage_weight[4] = {0.0, 0.5 * h, 0.5 * h, h};
  for (int i = 0; i < n; ++i) x0[i] = m->r[kModelStates[i]];
  for (int s = 0; s < 4; ++s) {
    m->time = t0 + stage_time[s];
    for (int i = 0; i < n; ++i) m->r[kModelStates[i]] = x0[i] + (s == 0 ? 0.0 : stage_weight[s] * k[s - 1][i]);
    ModelEvaluate(m);
    for (int i = 0; i < n; ++i) k[s][i] = m->r[kModelDerivatives[i]];
  }
  for (int i = 0; i < n; ++i) {
    m->r[kModelStates[i]] = x0[i] + h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
  }
  m->time = t0 + h;
  ModelEvaluate(m);
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real point, fmi2Real step, fmi2Boolean no_set_prior) {
  (void)no_set_prior;
  Model* m = (Model*)c;
  m->time = point;
  for (int j = 1; j <= kModelSubstepsPerStep; ++j) {
    const fmi2Real target = j == kModelSubstepsPerStep ? point + step : point + step * j / kModelSubstepsPerStep;
    /* A time event inside the substep: integrate to it exactly, then on. */
    while (m->next_event_time_defined && m->next_event_time > m->time && m->next_event_time <= target) {
      RungeKuttaStep(m, m->next_event_time - m->time);
      m->time = m->next_event_time;
      ModelEvent(m);
    }
    if (target > m->time) RungeKuttaStep(m, target - m->time);
    m->time = target;
  }
  return m->terminate ? fmi2Discard : fmi2OK;
}
