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

fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial) {
  const fmi2Real mass = m->r[kMass];
  *partial = 0.0;
  switch (unknown) {
    case kX: /* in initialization: x = x0 */
      if (known == kX) *partial = 1.0;
      if (known == kX0) *partial = 1.0;
      return fmi2OK;
    case kV: /* in initialization: v = 0 */
      if (known == kV) *partial = 1.0;
      return fmi2OK;
    case kDerX:
      if (known == kV) *partial = 1.0;
      return fmi2OK;
    case kDerV: /* (-k x - c v) / m */
      if (known == kX) *partial = -m->r[kStiffness] / mass;
      if (known == kV) *partial = -m->r[kDamping] / mass;
      if (known == kStiffness) *partial = -m->r[kX] / mass;
      if (known == kDamping) *partial = -m->r[kV] / mass;
      if (known == kMass) *partial = -m->r[kDerV] / mass;
      return fmi2OK;
    case kSpringForce: /* -k x */
      if (known == kX) *partial = -m->r[kStiffness];
      if (known == kStiffness) *partial = -m->r[kX];
      return fmi2OK;
    default:
      ModelLog(m, fmi2Error, "no directional derivative of the variable with value reference %g", (double)unknown);
      return fmi2Error;
  }
}
