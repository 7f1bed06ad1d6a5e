// The study's `sweep` or `sample` section -> spec::DesignSet, given the
// study's design variables already converted (an axis names one and must
// stay within its bounds). Problems go to `errors`.
#pragma once

#include "mbopt/v1/study.pb.h"
#include "spec/io/locator.h"
#include "spec/study.h"

namespace mbopt::spec::io {

DesignSet ConvertDesignSet(const v1::Study& message, const Study& study, const Where& where, Errors* errors);

// How `mbopt validate` names the form: "a sweep of k (9 points from 6 to
// 14, scaled)", "a grid of a (...) by b (...), 12 designs", "a Latin
// hypercube sample of 20 designs (seed 7)", or "an optimization".
std::string DescribeStudyForm(const Study& study);

}  // namespace mbopt::spec::io
