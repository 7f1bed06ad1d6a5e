// The report page's "Mechanism" section for one job: `mbopt-worker draw`
// draws the job's study (its scene inlined) at the initial and at the final
// design, as `mbopt report` analyses them for the responses.
#pragma once

#include "client/report/report_data.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// Fills data->mechanism: both drawings (for a study with load cases, both
// per case in `cases`, each with the parameters the case sets), or a note
// saying why not (no design yet, a scene kind without a drawing, the
// worker program not found, a motion that stops early). Prints a line on stderr while it runs.
// `deflection_scale` magnifies the flexible links' deflection on the page
// (report/deflection_scale.h; 1: true to scale).
void AddMechanismDrawings(const v1::GetJobResponse& job, report::ReportData* data, double deflection_scale = 1.0);

}  // namespace mbopt::client
