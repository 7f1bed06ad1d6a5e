// The study's `pareto` section -> spec::Pareto, given the study's objective,
// constraints and design set already converted: it names a one-sided
// constraint (its largest value is the front's second objective), the
// study has an objective to trade it against, and no sweep or sample.
// Problems go to `errors`.
#pragma once

#include "mbopt/v1/study.pb.h"
#include "spec/io/locator.h"
#include "spec/study.h"

namespace mbopt::spec::io {

Pareto ConvertPareto(const v1::Study& message, const Study& study, const Where& where, Errors* errors);

// How `mbopt validate` names a Pareto study: "a Pareto front of the
// objective against the largest value of s1 (in), 9 points".
std::string DescribePareto(const Study& study);

}  // namespace mbopt::spec::io
