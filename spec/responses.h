// Named responses (spec::Response): series computed from an analysis'
// outputs, instant by instant, and their derivatives by the chain rule. They
// run after the engine, on the worker, so the optimizer and the analysis log
// see only the study values built from them. Pure.
//
// Shapes: a response has as many series as the widest signal it reads (every
// signal it reads has that many series or one, which is then used for each),
// and a value per grid instant, unless it reads no time series and not t:
// then it is a scalar, like mass. A response of parameters only is a
// function of the design alone: a constraint on it is a constraint on the
// design variables, exact in the optimizer's linearization when linear.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::spec {

using Series = std::vector<std::vector<double>>;  // [series][instant], SI

// The shape of response `r` given the shapes of the signals before it
// (`shapes` holds at least the scene's outputs and responses 0 .. r-1).
// InvalidArgument naming the response when two signals it reads have
// different numbers of series.
absl::StatusOr<OutputShape> ResponseShape(const Study& study, int response, const std::vector<OutputShape>& shapes,
                                          int instants);

// Every response's series at one analysis. `signals` holds the scene's
// outputs (as for ComputeStudyValues) and is extended with the responses, in
// order, which point into `storage`. A non-finite value is passed through.
void AppendResponses(const Study& study, const StudyLayout& layout, const std::vector<double>& parameter_values_si,
                     std::vector<Series>* storage, std::vector<const Series*>* signals);

// The responses' derivatives: `derivatives[i]` holds d signal / d (SI value
// of variable i's parameter) for the scene's outputs and is extended with the
// responses'. `signals` must already hold the responses (AppendResponses).
// A parameter the expression reads directly contributes its own partial when
// variable i sets it (its parameter or also_sets).
void AppendResponseDerivatives(const Study& study, const StudyLayout& layout,
                               const std::vector<double>& parameter_values_si,
                               const std::vector<const Series*>& signals, std::vector<std::vector<Series>>* storage,
                               std::vector<std::vector<const Series*>>* derivatives);

}  // namespace mbopt::spec
