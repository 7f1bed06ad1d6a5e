// A design set's job (GetJobResponse of a sweep or sample) as the data of
// its report page (client/report/design_set_report.h).
#pragma once

#include <vector>

#include "client/report/design_set_report.h"
#include "mbopt/v1/service.pb.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::client {

// Per study constraint, how its normalized value reads in its unit: known
// when all its rows share one limit and one scale (a MAX, MIN or MAX_ABS
// limit, a whole-series reduction bounded on one side); an equality, a
// two-sided band or rows of different limits stay normalized.
std::vector<report::DesignSetReportData::ConstraintInUnit> ConstraintsInUnit(const spec::Study& study,
                                                                            const spec::StudyLayout& layout);

report::DesignSetReportData DesignSetReportFromJob(const v1::GetJobResponse& job);

}  // namespace mbopt::client
