/* The FMI 3.0 C interface as the importer and the project's test models see
 * it: the scalar types, the logger callback and the function types of Model
 * Exchange and Co-Simulation that mbopt calls, declared from the published
 * FMI 3.0 standard (names and signatures are the standard's, so an FMU built
 * against the standard's headers is binary compatible with these).
 *
 * Plain C (C99) so that the test models include it too. Not declared:
 * Scheduled Execution, clocks, FMU state serialization, the getters and
 * setters of types other than Float64 (mbopt refuses FMUs that need them). */
#ifndef MBOPT_WORKER_FMU_FMI3_API_H_
#define MBOPT_WORKER_FMU_FMI3_API_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef void* fmi3Instance;
typedef void* fmi3InstanceEnvironment;
typedef double fmi3Float64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char* fmi3String;
typedef uint32_t fmi3ValueReference;

#define fmi3True true
#define fmi3False false

typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;

/* Unlike FMI 2.0's logger, the message arrives formatted. */
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment environment, fmi3Status status,
                                       fmi3String category, fmi3String message);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment environment, fmi3Float64 update_time,
                                               fmi3Boolean variable_set_requested,
                                               fmi3Boolean variable_get_allowed, fmi3Boolean step_finished,
                                               fmi3Boolean can_return_early, fmi3Boolean* early_return_requested,
                                               fmi3Float64* early_return_time);

/* Common to both interface types. */
typedef const char* fmi3GetVersionTYPE(void);
typedef fmi3Instance fmi3InstantiateModelExchangeTYPE(fmi3String instance_name, fmi3String instantiation_token,
                                                      fmi3String resource_path, fmi3Boolean visible,
                                                      fmi3Boolean logging_on, fmi3InstanceEnvironment environment,
                                                      fmi3LogMessageCallback log_message);
typedef fmi3Instance fmi3InstantiateCoSimulationTYPE(
    fmi3String instance_name, fmi3String instantiation_token, fmi3String resource_path, fmi3Boolean visible,
    fmi3Boolean logging_on, fmi3Boolean event_mode_used, fmi3Boolean early_return_allowed,
    const fmi3ValueReference required_intermediate_variables[], size_t n_required_intermediate_variables,
    fmi3InstanceEnvironment environment, fmi3LogMessageCallback log_message,
    fmi3IntermediateUpdateCallback intermediate_update);
typedef void fmi3FreeInstanceTYPE(fmi3Instance instance);
typedef fmi3Status fmi3EnterInitializationModeTYPE(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                                   fmi3Float64 tolerance, fmi3Float64 start_time,
                                                   fmi3Boolean stop_time_defined, fmi3Float64 stop_time);
typedef fmi3Status fmi3ExitInitializationModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3EnterEventModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3TerminateTYPE(fmi3Instance instance);
typedef fmi3Status fmi3GetFloat64TYPE(fmi3Instance instance, const fmi3ValueReference value_references[],
                                      size_t n_value_references, fmi3Float64 values[], size_t n_values);
typedef fmi3Status fmi3SetFloat64TYPE(fmi3Instance instance, const fmi3ValueReference value_references[],
                                      size_t n_value_references, const fmi3Float64 values[], size_t n_values);
typedef fmi3Status fmi3GetDirectionalDerivativeTYPE(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                    size_t n_unknowns, const fmi3ValueReference knowns[],
                                                    size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
                                                    fmi3Float64 sensitivity[], size_t n_sensitivity);
typedef fmi3Status fmi3UpdateDiscreteStatesTYPE(fmi3Instance instance, fmi3Boolean* discrete_states_need_update,
                                                fmi3Boolean* terminate_simulation,
                                                fmi3Boolean* nominals_of_continuous_states_changed,
                                                fmi3Boolean* values_of_continuous_states_changed,
                                                fmi3Boolean* next_event_time_defined, fmi3Float64* next_event_time);

/* Model Exchange. */
typedef fmi3Status fmi3EnterContinuousTimeModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3CompletedIntegratorStepTYPE(fmi3Instance instance,
                                                   fmi3Boolean no_set_fmu_state_prior_to_current_point,
                                                   fmi3Boolean* enter_event_mode,
                                                   fmi3Boolean* terminate_simulation);
typedef fmi3Status fmi3SetTimeTYPE(fmi3Instance instance, fmi3Float64 time);
typedef fmi3Status fmi3SetContinuousStatesTYPE(fmi3Instance instance, const fmi3Float64 continuous_states[],
                                               size_t n_continuous_states);
typedef fmi3Status fmi3GetContinuousStateDerivativesTYPE(fmi3Instance instance, fmi3Float64 derivatives[],
                                                         size_t n_continuous_states);
typedef fmi3Status fmi3GetEventIndicatorsTYPE(fmi3Instance instance, fmi3Float64 event_indicators[],
                                              size_t n_event_indicators);
typedef fmi3Status fmi3GetContinuousStatesTYPE(fmi3Instance instance, fmi3Float64 continuous_states[],
                                               size_t n_continuous_states);

/* Co-Simulation. */
typedef fmi3Status fmi3DoStepTYPE(fmi3Instance instance, fmi3Float64 current_communication_point,
                                  fmi3Float64 communication_step_size,
                                  fmi3Boolean no_set_fmu_state_prior_to_current_point,
                                  fmi3Boolean* event_handling_needed, fmi3Boolean* terminate_simulation,
                                  fmi3Boolean* early_return, fmi3Float64* last_successful_time);

#ifdef __cplusplus
}
#endif

#endif /* MBOPT_WORKER_FMU_FMI3_API_H_ */
