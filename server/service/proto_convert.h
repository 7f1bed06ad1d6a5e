// Domain types of the job manager <-> mbopt.v1 messages. Pure translation:
// names for row indices, physical values (scale * x) for scaled designs.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "mbopt/v1/service.pb.h"
#include "mbopt/v1/study.pb.h"
#include "server/jobs/manager/job_manager.h"
#include "spec/study.h"

namespace mbopt::service {

v1::JobState ToProto(jobs::JobState state);
v1::JobSummary ToProto(const jobs::manager::JobSummaryData& summary);
// `layout` (may be null: rows go out as "row N"), `variable_scales` and
// `objective_sign` as in JobView: the objective values go out as reported (a
// maximized value as itself).
v1::CycleRecord ToProto(const slp::CycleRecord& record, const spec::StudyLayout* layout,
                        const std::vector<double>& variable_scales, double objective_sign);
// The same with what the job's view knows: its rows' names, the variables'
// scales, the sign of each record's F and a front's shown values.
v1::CycleRecord ToProto(const slp::CycleRecord& record, const jobs::manager::JobView& view);

// A worker's result as the job manager takes it (the job's intake then
// validates the record). `holder`: the name of the token that sent it.
jobs::manager::WorkerReport WorkerReportFromProto(const v1::TaskResult& result, const std::string& holder);

// Sets the message-typed field `field_number` of `out` (left unset there) to
// `serialized`, a message of the field's type serialized already, without
// parsing it: protobuf writes unknown fields as they are, and the receiver
// reads a length-delimited field of that number as the field. So a study
// goes to workers and readers as the bytes its user sent.
void SetSerializedMessageField(int field_number, const std::string& serialized, google::protobuf::Message* out);

// The study decoder of the job manager: binary mbopt.v1.Study -> validated
// study (spec/io), InvalidArgument with the loader's message.
absl::StatusOr<spec::Study> DecodeStudy(const std::string& bytes, const std::string& source_name);

}  // namespace mbopt::service
