// Study message -> spec::Study, given its scene already converted: binds
// design variables to parameters, checks bounds and initial values, resolves
// the objective's and constraints' outputs and units, fills optimizer
// defaults, and applies the AnalysisOverrides to the scene. Problems go to
// `errors`; the returned study is meaningful only if none were added.
#pragma once

#include "mbopt/v1/study.pb.h"
#include "spec/io/locator.h"
#include "spec/study.h"

namespace mbopt::spec::io {

Study ConvertStudy(const v1::Study& message, Scene scene, const Where& where, Errors* errors);

}  // namespace mbopt::spec::io
