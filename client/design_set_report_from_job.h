// A design set's job (GetJobResponse of a sweep or sample) as the data of
// its report page (client/report/design_set_report.h).
#pragma once

#include "client/report/design_set_report.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

report::DesignSetReportData DesignSetReportFromJob(const v1::GetJobResponse& job);

}  // namespace mbopt::client
