// Scene message -> spec::Scene: resolves names to indices, converts units to
// SI, and checks everything a person can get wrong (unknown names, wrong
// units, non-positive masses, zero directions, an output the model cannot
// produce, an empty time grid, ...). Problems go to `errors`; the returned
// scene is meaningful only if none were added.
#pragma once

#include "mbopt/v1/scene.pb.h"
#include "spec/io/locator.h"
#include "spec/scene.h"

namespace mbopt::spec::io {

Scene ConvertScene(const v1::Scene& message, const Where& where, Errors* errors);

}  // namespace mbopt::spec::io
