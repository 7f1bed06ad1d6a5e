// The rows of the job database as plain structs. Analyses are stored as the
// server's one analysis record (server/jobs/analysis_record.h). The store
// does not know protobuf or the SLP core: studies and cycle records arrive as opaque bytes
// serialized by the layers that own their formats (the service serializes the
// study as a binary mbopt.v1.Study; server/jobs encodes cycle records), and
// the store keeps them bit for bit. Doubles of analyses are kept exactly
// (double_blob.h), which is what a bit-identical resume needs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbopt::store {

struct JobRow {
  std::string id;               // "job-<seq>", assigned by the store
  std::int64_t seq = 0;         // creation order, 1-based
  std::string study_name;
  std::string source_name;      // the study file's path, for messages
  std::string study;            // opaque bytes (serialized study)
  std::string state;            // a job state name (server/jobs/job_state.h)
  std::string message;          // failure, stall or interruption reason
  std::int64_t created_unix_ms = 0;
  std::int64_t updated_unix_ms = 0;
  // Progress, updated in the same transaction as the cycle records.
  std::int64_t records = 0;     // cycle records committed
  std::int32_t cycles = 0;      // cycles completed
  std::int64_t analyses = 0;    // analyses consumed by the optimizer
  double wall_seconds = 0;      // running time, not counting interruptions
  std::string owner;            // who submitted it (a token's name); "" on a server without tokens
};


// One cycle record (one LP solve and its trial point) of a job.
struct CycleRow {
  std::int64_t index = 0;       // 0-based position in the job's record log
  std::int32_t cycle = 0;
  std::int32_t attempt = 0;
  std::string record;           // opaque bytes (server/jobs/record_codec.h)
};

// What a cycle commit changes on the job row, atomically with the records.
struct JobProgress {
  std::string state;
  std::string message;
  std::int32_t cycles = 0;
  std::int64_t analyses = 0;
  double wall_seconds = 0;
};

// An event to log with a change of the job (Store::CreateJob, SetJobState,
// JobWrite): in the same transaction, so the change and its line in the
// event log are one commit (and one sync).
struct NewEvent {
  std::string kind;
  std::string message;
};

struct EventRow {
  std::int64_t id = 0;
  std::string job_id;
  std::int64_t unix_ms = 0;
  std::string kind;             // "submitted", "resumed", "interrupted", ...
  std::string message;
};

// How many of a job's analyses one token holder's workers delivered.
struct AnalysesByHolder {
  std::string holder;  // "" for analyses attributed to no token
  std::int64_t analyses = 0;
};

}  // namespace mbopt::store
