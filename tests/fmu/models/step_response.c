/* A first-order lag y' = (u - y) / tau whose input u steps from 0 to 1 at
 * t_step: a time event (nextEventTime). From y(0) = 0,
 * y(t) = 1 - exp(-(t - t_step) / tau) after the step. */
#include "tests/fmu/models/model.h"

enum { kY, kDerY, kTau, kStepTime, kInput, kNumReals };

const char* const kModelGuid = "{mbopt-test-step-response-1}";
const int kModelNumReals = kNumReals;
const int kModelNumStates = 1;
const fmi2ValueReference kModelStates[] = {kY};
const fmi2ValueReference kModelDerivatives[] = {kDerY};
const int kModelNumEventIndicators = 0;
const int kModelSubstepsPerStep = 10;

void ModelSetStartValues(Model* m) {
  m->r[kTau] = 0.5;
  m->r[kStepTime] = 0.3;
  m->r[kInput] = 0.0;
  m->r[kY] = 0.0;
}

/* The input and the next time event from the time: the same at
 * initialization and at the event. */
static fmi2Boolean UpdateInput(Model* m) {
  const fmi2Real before = m->r[kInput];
  m->r[kInput] = m->time >= m->r[kStepTime] ? 1.0 : 0.0;
  m->next_event_time_defined = m->time < m->r[kStepTime];
  m->next_event_time = m->r[kStepTime];
  return before != m->r[kInput];
}

fmi2Status ModelInitialize(Model* m) {
  if (!(m->r[kTau] > 0.0)) {
    ModelLog(m, fmi2Error, "tau_s must be > 0, got %g", m->r[kTau]);
    return fmi2Error;
  }
  m->r[kY] = 0.0;
  UpdateInput(m);
  return fmi2OK;
}

void ModelEvaluate(Model* m) { m->r[kDerY] = (m->r[kInput] - m->r[kY]) / m->r[kTau]; }

void ModelEventIndicators(const Model* m, fmi2Real* indicators) {
  (void)m;
  (void)indicators;
}

fmi2Boolean ModelEvent(Model* m) {
  UpdateInput(m);
  /* The input is discrete; the state y does not jump. */
  return fmi2False;
}

fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial) {
  const fmi2Real tau = m->r[kTau];
  *partial = 0.0;
  switch (unknown) {
    case kY: /* in initialization: y = 0 */
      if (known == kY) *partial = 1.0;
      return fmi2OK;
    case kDerY: /* (u - y) / tau */
      if (known == kY) *partial = -1.0 / tau;
      if (known == kTau) *partial = -m->r[kDerY] / tau;
      return fmi2OK;
    default:
      ModelLog(m, fmi2Error, "no directional derivative of the variable with value reference %g", (double)unknown);
      return fmi2Error;
  }
}
