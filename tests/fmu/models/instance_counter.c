/* A model that counts, in a global of its library, the instances made
 * since the library was loaded, and outputs the count its own instance
 * saw: 1 for every instance when each load has a copy of the library of
 * its own, 2 for the second instance when two loads share one. Its one
 * state stays at 0. */
#include "tests/fmu/models/model.h"

enum { kY, kDerY, kInstancesSeen, kNumReals };

const char* const kModelGuid = "{mbopt-test-instance-counter-1}";
const int kModelNumReals = kNumReals;
const int kModelNumStates = 1;
const fmi2ValueReference kModelStates[] = {kY};
const fmi2ValueReference kModelDerivatives[] = {kDerY};
const int kModelNumEventIndicators = 0;
const int kModelSubstepsPerStep = 1;

static int instances_made = 0;

void ModelSetStartValues(Model* m) {
  ++instances_made;
  m->r[kY] = 0.0;
  m->r[kInstancesSeen] = (fmi2Real)instances_made;
}

fmi2Status ModelInitialize(Model* m) {
  (void)m;
  return fmi2OK;
}

void ModelEvaluate(Model* m) { m->r[kDerY] = 0.0; }

void ModelEventIndicators(const Model* m, fmi2Real* indicators) {
  (void)m;
  (void)indicators;
}

fmi2Boolean ModelEvent(Model* m) {
  (void)m;
  return fmi2False;
}

fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial) {
  (void)unknown;
  (void)known;
  *partial = 0.0;
  ModelLog(m, fmi2Error, "no directional derivatives (value reference %g)", (double)unknown);
  return fmi2Error;
}
