/* A ball dropped from height h0 onto the floor h = 0, bouncing back with
 * the restitution coefficient e: a state event (the event indicator is h)
 * reverses and scales its velocity. Impact times: t1 = sqrt(2 h0 / g), then
 * each flight lasts e times the one before (tests/fmu/closed_forms.h). */
#include "tests/fmu/models/model.h"

enum { kHeight, kVelocity, kDerHeight, kDerVelocity, kGravity, kRestitution, kHeight0, kNumReals };

const char* const kModelGuid = "{mbopt-test-bouncing-ball-1}";
const int kModelNumReals = kNumReals;
const int kModelNumStates = 2;
const fmi2ValueReference kModelStates[] = {kHeight, kVelocity};
const fmi2ValueReference kModelDerivatives[] = {kDerHeight, kDerVelocity};
const int kModelNumEventIndicators = 1;
const int kModelSubstepsPerStep = 10;

void ModelSetStartValues(Model* m) {
  m->r[kGravity] = 9.81;
  m->r[kRestitution] = 0.8;
  m->r[kHeight0] = 1.0;
  m->r[kHeight] = m->r[kHeight0];
}

fmi2Status ModelInitialize(Model* m) {
  if (!(m->r[kHeight0] > 0.0)) {
    ModelLog(m, fmi2Error, "h0_m must be > 0, got %g", m->r[kHeight0]);
    return fmi2Error;
  }
  m->r[kHeight] = m->r[kHeight0];
  m->r[kVelocity] = 0.0;
  return fmi2OK;
}

void ModelEvaluate(Model* m) {
  m->r[kDerHeight] = m->r[kVelocity];
  m->r[kDerVelocity] = -m->r[kGravity];
}

void ModelEventIndicators(const Model* m, fmi2Real* indicators) { indicators[0] = m->r[kHeight]; }

fmi2Boolean ModelEvent(Model* m) {
  if (m->r[kHeight] <= 0.0 && m->r[kVelocity] < 0.0) {
    /* On the floor exactly, so that the indicator starts the next flight at 0. */
    m->r[kHeight] = 0.0;
    m->r[kVelocity] = -m->r[kRestitution] * m->r[kVelocity];
    return fmi2True;
  }
  return fmi2False;
}

fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial) {
  (void)known;
  *partial = 0.0;
  ModelLog(m, fmi2Error, "this model declares no directional derivatives (asked for value reference %g)",
           (double)unknown);
  return fmi2Error;
}
