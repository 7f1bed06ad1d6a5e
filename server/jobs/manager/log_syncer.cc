#include "server/jobs/manager/log_syncer.h"

#include <iostream>
#include <utility>
#include <vector>

namespace mbopt::jobs::manager {

LogSyncer::LogSyncer(std::function<absl::Status()> sync,
                     std::function<bool(const std::string& job_id, std::int64_t synced)> publish,
                     std::function<void()> before_sync)
    : sync_(std::move(sync)), publish_(std::move(publish)), before_sync_(std::move(before_sync)) {
  thread_ = std::thread([this] { Loop(); });
}

LogSyncer::~LogSyncer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wanted_.notify_all();
  thread_.join();
}

std::int64_t LogSyncer::CommittedWithoutSync(const std::string& job_id) {
  std::int64_t commit = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    commit = ++commits_;
    waiting_.insert(job_id);
  }
  wanted_.notify_one();
  return commit;
}

void LogSyncer::WaitUntilIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return stopping_ || (waiting_.empty() && !syncing_); });
}

void LogSyncer::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wanted_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
    if (waiting_.empty()) return;  // stopping, nothing left
    std::set<std::string> jobs;
    jobs.swap(waiting_);
    syncing_ = true;
    // Every commit counted so far has returned: the sync makes it durable.
    const std::int64_t synced = commits_;
    lock.unlock();
    if (before_sync_) before_sync_();
    if (absl::Status status = sync_(); !status.ok()) {
      std::cerr << "mbopt-server: cannot sync the job log: " << status << std::endl;
    }
    std::vector<std::string> still_waiting;
    for (const std::string& id : jobs) {
      if (!publish_(id, synced)) still_waiting.push_back(id);
    }
    lock.lock();
    waiting_.insert(still_waiting.begin(), still_waiting.end());
    syncing_ = false;
    done_.notify_all();
  }
}

}  // namespace mbopt::jobs::manager
