// One optimization on the server: a study, its layout, and the SLP
// optimizer that runs it. A Job is pure bookkeeping around the optimizer: it
// does no I/O and takes no locks (the owner serializes calls); the server's
// job manager feeds it results, logs what it emits and schedules what it asks
// for.
//
// Resume: a fresh Job is given the logged analysis results (Replay). It hands
// them to the optimizer in the order the optimizer asks for them, which
// rebuilds the optimizer's state bit for bit, and compares each record the
// optimizer emits again with the logged one. Afterwards only analyses not in
// the log are pending.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/slp/slp_optimizer.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::jobs {

// A logged analysis result with the design point it was computed at.
struct LoggedAnalysis {
  slp::AnalysisResult result;
  std::vector<double> x_scaled;
};

class Job {
 public:
  // InvalidArgument (naming the study's file and field) when the study
  // cannot be laid out or gives an invalid problem or options.
  static absl::StatusOr<std::unique_ptr<Job>> Create(spec::Study study);

  const spec::Study& study() const { return study_; }
  const spec::StudyLayout& layout() const { return layout_; }
  const slp::ProblemSpec& problem() const { return optimizer_->spec(); }
  const slp::SlpOptions& options() const { return options_; }
  const slp::SlpOptimizer& optimizer() const { return *optimizer_; }

  std::vector<slp::AnalysisRequest> PendingRequests() const { return optimizer_->PendingRequests(); }

  // Replays `logged` (any order; each used when the optimizer asks for its
  // request id) and checks the re-emitted records against
  // `logged_records` (encoded, record_codec.h). Returns the records emitted
  // beyond the logged ones (a crash between an analysis commit and its
  // cycle commit leaves those): the caller logs them now. DataLoss if a
  // logged design point or record differs from what the optimizer produces
  // now (non-determinism, or a database from another build), or if the log
  // holds more records than the replay produces.
  absl::StatusOr<std::vector<slp::CycleRecord>> Replay(const std::vector<LoggedAnalysis>& logged,
                                                       const std::vector<std::string>& logged_records);

  // Hands one result to the optimizer and returns the records it emitted.
  // InvalidArgument for an unknown or answered request, or wrong sizes.
  absl::StatusOr<std::vector<slp::CycleRecord>> Submit(const slp::AnalysisResult& result);

  // Physical design values (parameter value = scale * x, in the parameter's
  // unit) of a scaled design.
  std::vector<double> PhysicalDesign(const Eigen::VectorXd& x_scaled) const;

 private:
  Job(spec::Study study, spec::StudyLayout layout, slp::SlpOptions options,
      std::unique_ptr<slp::SlpOptimizer> optimizer);

  spec::Study study_;
  spec::StudyLayout layout_;
  slp::SlpOptions options_;
  std::unique_ptr<slp::SlpOptimizer> optimizer_;
};

}  // namespace mbopt::jobs
