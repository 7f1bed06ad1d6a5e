/* The Van der Pol oscillator x'' - mu (1 - x^2) x' + x = 0 from x = 2,
 * x' = 0: no closed form, but its limit cycle's amplitude and period are
 * known to many digits (tests/fmu/closed_forms.h). */
#include "tests/fmu/models/model.h"

enum { kX0, kX1, kDerX0, kDerX1, kMu, kNumReals };

const char* const kModelGuid = "{mbopt-test-van-der-pol-1}";
const int kModelNumReals = kNumReals;
const int kModelNumStates = 2;
const fmi2ValueReference kModelStates[] = {kX0, kX1};
const fmi2ValueReference kModelDerivatives[] = {kDerX0, kDerX1};
const int kModelNumEventIndicators = 0;
const int kModelSubstepsPerStep = 10;

void ModelSetStartValues(Model* m) {
  m->r[kX0] = 2.0;
  m->r[kX1] = 0.0;
  m->r[kMu] = 1.0;
}

fmi2Status ModelInitialize(Model* m) {
  (void)m;
  return fmi2OK;
}

void ModelEvaluate(Model* m) {
  m->r[kDerX0] = m->r[kX1];
  m->r[kDerX1] = m->r[kMu] * (1.0 - m->r[kX0] * m->r[kX0]) * m->r[kX1] - m->r[kX0];
}

void ModelEventIndicators(const Model* m, fmi2Real* indicators) {
  (void)m;
  (void)indicators;
}

fmi2Boolean ModelEvent(Model* m) {
  (void)m;
  return fmi2False;
}

fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial) {
  (void)known;
  *partial = 0.0;
  ModelLog(m, fmi2Error, "this model declares no directional derivatives (asked for value reference %g)",
           (double)unknown);
  return fmi2Error;
}
