// How the CLI names parts of a study in what it prints (validate) and in
// the report page's titles: reductions and time windows.
#pragma once

#include <string>

#include "spec/study.h"

namespace mbopt::client {

// "max", "max_abs", "rms", ... as study files spell them, without the prefix.
const char* ReductionName(spec::Reduction reduction);

// "" for the whole grid, else " from 0.5 s to the end" and the like.
std::string WindowText(const spec::TimeWindow& window);

}  // namespace mbopt::client
