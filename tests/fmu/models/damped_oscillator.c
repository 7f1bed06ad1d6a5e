/* m x'' + c x' + k x = 0 from x(0) = x0, x'(0) = 0: the closed form of the
 * underdamped case is in tests/fmu/closed_forms.h. SI units. */
#include "tests/fmu/models/model.h"

enum { kX, kV, kDerX, kDerV, kMass, kDamping, kStiffness, kX0, kSpringForce, kNumReals };

const char* const kModelGuid = "{mbopt-test-damped-oscillator-1}";
const int kModelNumReals = kNumReals;
const int kModelNumStates = 2;
const fmi2ValueReference kModelStates[] = {kX, kV};
const fmi2ValueReference kModelDerivatives[] = {kDerX, kDerV};
const int kModelNumEventIndicators = 0;
const int kModelSubstepsPerStep = 10;

void ModelSetStartValues(Model* m) {
  m->r[kMass] = 1.0;
  m->r[kDamping] = 0.4;
  m->r[kStiffness] = 4.0;
  m->r[kX0] = 0.1;
  m->r[kX] = m->r[kX0];
}

fmi2Status ModelInitialize(Model* m) {
  if (!(m->r[kMass] > 0.0)) {
    ModelLog(m, fmi2Error, "mass_kg must be > 0, got %g", m->r[kMass]);
    return fmi2Error;
  }
  m->r[kX] = m->r[kX0];
  m->r[kV] = 0.0;
  return fmi2OK;
}

void ModelEvaluate(Model* m) {
  m->r[kSpringForce] = -m->r[kStiffness] * m->r[kX];
  m->r[kDerX] = m->r[kV];
  m->r[kDerV] = (m->r[kSpringForce] - m->r[kDamping] * m->r[kV]) / m->r[kMass];
}

void ModelEventIndicators(const Model* m, fmi2Real* indicators) {
  (void)m;
  (void)indicators;
}

fmi2Boolean ModelEvent(Model* m) {
  (void)m;
  return fmi2False;
}
