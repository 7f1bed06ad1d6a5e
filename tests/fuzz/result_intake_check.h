// The check of the result_intake fuzzing target: a batch of results as a
// hostile worker could send it (a binary mbopt.v1.TaskResults), given to the
// server's result intake (the service's translation, WorkerReportFromProto,
// then JobManager::ReportResults) of a real server without its network: a
// store on disk, the scheduler, two jobs of the oscillator study (one with
// finite differences, one with simulator sensitivities) and two registered
// workers, one of which holds every task on offer.
//
// So that mutated inputs reach past the id checks, a result's empty fields
// are filled from the world: an empty worker id is the lease holder's, "B"
// the other worker's; an empty task id (or "#K") is the K-th leased task's,
// and a request id of 0 and an empty job id are that task's.
//
// What must hold, or the check aborts with a message:
//   - every answer is accepted or refused with InvalidArgument,
//     PermissionDenied, NotFound or FailedPrecondition (never another code);
//   - a batch from workers that hold none of its tasks' leases changes no
//     job and no lease (and none of its results is accepted);
//   - a server restarted on the same database right after the batch (as
//     after a crash) resumes every job without failing its replay, with the
//     same cycle records;
//   - honest answers after that take every job to its end (no task lost,
//     no job stuck).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mbopt::fuzz {

void CheckResultIntake(std::string_view data);

// Honest batches (the first tasks' exact answers, with and without
// gradients), a failed analysis, a retry, and results for another worker's
// tasks: binary mbopt.v1.TaskResults the target starts from.
std::vector<std::string> ResultIntakeSeeds();

}  // namespace mbopt::fuzz
