/* The test models' side of the FMI interface: model_frame.c implements the
 * fmi2 functions once, model_frame3.c the fmi3 ones, over a model that keeps
 * all its Real variables in one array indexed by value reference and
 * supplies the functions below. Each test FMU is one frame plus one model
 * file; the FMI 3.0 frame maps the fmi2 types and statuses used here onto
 * its own (the statuses have the same values in both versions). */
#ifndef MBOPT_TESTS_FMU_MODELS_MODEL_H_
#define MBOPT_TESTS_FMU_MODELS_MODEL_H_

#include "worker/fmu/fmi2_api.h"

#define MODEL_MAX_REALS 16

typedef struct {
  fmi2Real time;
  fmi2Real r[MODEL_MAX_REALS];
  fmi2Boolean next_event_time_defined;
  fmi2Real next_event_time;
  fmi2Boolean terminate;
  fmi2CallbackFunctions callbacks;
  fmi2Type type;
  char instance_name[64];
} Model;

/* Supplied by each model. */
extern const char* const kModelGuid;
extern const int kModelNumReals;
extern const int kModelNumStates;
extern const fmi2ValueReference kModelStates[];
extern const fmi2ValueReference kModelDerivatives[];
extern const int kModelNumEventIndicators;
/* Runge-Kutta steps per communication step of fmi2DoStep. */
extern const int kModelSubstepsPerStep;

void ModelSetStartValues(Model* m);
/* At the end of initialization: states from parameters, the first time
 * event; fmi2Error (with a message logged) for parameters out of range. */
fmi2Status ModelInitialize(Model* m);
/* Derivatives and other dependent variables from time, states, parameters. */
void ModelEvaluate(Model* m);
void ModelEventIndicators(const Model* m, fmi2Real* indicators);
/* At an event: discrete changes and state jumps, the next time event.
 * Returns whether a continuous state changed. */
fmi2Boolean ModelEvent(Model* m);

/* d unknown / d known at the current values, for the frames'
 * fmi2/fmi3GetDirectionalDerivative: unknowns are derivatives and outputs
 * (knowns: states and tunable parameters) and, in initialization, states
 * (knowns: parameters). fmi2Error (with a message logged) for a pair the
 * model does not differentiate; models that declare no directional
 * derivatives answer so for every pair. */
fmi2Status ModelPartialDerivative(Model* m, fmi2ValueReference unknown, fmi2ValueReference known, fmi2Real* partial);

void ModelLog(const Model* m, fmi2Status status, const char* message, double value);

#endif /* MBOPT_TESTS_FMU_MODELS_MODEL_H_ */
