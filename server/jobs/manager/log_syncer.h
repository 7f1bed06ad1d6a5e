// The job manager's log-syncing thread (at store::Durability::kCycles).
// A job's cycle records committed without a sync are durable against a
// crash of the process but not yet against a power loss; they wait until
// one sync of the log covers their commit, and only then are they
// published to views. Commits are numbered in the order they returned; a
// sync covers every commit numbered before it started.
//
// Thread-safe. The thread runs until the syncer is destroyed.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "absl/status/status.h"

namespace mbopt::jobs::manager {

class LogSyncer {
 public:
  // `sync` syncs the log. `publish(job_id, synced)` publishes the job's
  // records of commits numbered up to `synced` and says whether none of its
  // records waits any more. `before_sync` (may be empty) runs before each
  // sync: a test's hook. A failed sync is logged; the records are published
  // all the same (only a power loss could take them, as at kNormal).
  LogSyncer(std::function<absl::Status()> sync,
            std::function<bool(const std::string& job_id, std::int64_t synced)> publish,
            std::function<void()> before_sync);
  // Finishes the round under way and stops.
  ~LogSyncer();
  LogSyncer(const LogSyncer&) = delete;
  LogSyncer& operator=(const LogSyncer&) = delete;

  // A commit of the job's records without a sync has returned: its number
  // (to compare with publish's `synced`); wakes the thread.
  std::int64_t CommittedWithoutSync(const std::string& job_id);
  // Waits until no job's records wait for a sync.
  void WaitUntilIdle();

 private:
  void Loop();

  std::function<absl::Status()> sync_;
  std::function<bool(const std::string&, std::int64_t)> publish_;
  std::function<void()> before_sync_;

  std::mutex mutex_;  // guards the five below
  std::condition_variable wanted_;
  std::condition_variable done_;
  bool syncing_ = false;          // a sync round is under way
  std::set<std::string> waiting_;  // jobs with records waiting for a sync
  std::int64_t commits_ = 0;      // commits of records without a sync so far
  bool stopping_ = false;
  std::thread thread_;  // started last: it reads the members above
};

}  // namespace mbopt::jobs::manager
