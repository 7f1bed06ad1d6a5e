#include "worker/service/stop_signal.h"

#include <pthread.h>
#include <signal.h>

#include <thread>

namespace mbopt::worker {

void StopSignal::Stop() {
  std::vector<std::function<void()>> callbacks;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return;
    stopped_ = true;
    callbacks.swap(callbacks_);
  }
  cv_.notify_all();
  for (auto& callback : callbacks) callback();
}

bool StopSignal::stopped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stopped_;
}

bool StopSignal::WaitFor(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  if (stopped_) return true;
  if (wait_observer_) wait_observer_(timeout);
  return cv_.wait_for(lock, timeout, [this] { return stopped_; });
}

void StopSignal::OnWaitBlocks(std::function<void(std::chrono::milliseconds)> observer) {
  std::lock_guard<std::mutex> lock(mutex_);
  wait_observer_ = std::move(observer);
}

void StopSignal::OnStop(std::function<void()> callback) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!stopped_) {
      callbacks_.push_back(std::move(callback));
      return;
    }
  }
  callback();
}

void StopOnTerminationSignals(StopSignal* stop) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread([stop, set] {
    int sig = 0;
    while (sigwait(&set, &sig) != 0) {
    }
    stop->Stop();
  }).detach();
}

}  // namespace mbopt::worker
