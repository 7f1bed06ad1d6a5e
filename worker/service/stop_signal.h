// A stop request shared by a worker's threads: set once (by SIGTERM/SIGINT or
// by a caller), observed by loops and by waits that should end early.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <vector>

namespace mbopt::worker {

class StopSignal {
 public:
  void Stop();
  bool stopped() const;
  // Waits up to `timeout`; true if stop was requested (at once if already).
  bool WaitFor(std::chrono::milliseconds timeout) const;
  // Runs `callback` when Stop() is called (at once if already stopped), on
  // the stopping thread; used to cancel blocking RPCs.
  void OnStop(std::function<void()> callback);
  // Runs `observer` with the timeout each time a WaitFor is about to block
  // (stop not requested yet), with the signal's lock held: a Stop() that
  // follows meets a waiting thread. It must not call the StopSignal. For
  // tests that must stop a worker while it waits (its reconnection backoff),
  // not before it gets there.
  void OnWaitBlocks(std::function<void(std::chrono::milliseconds)> observer);

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  bool stopped_ = false;
  std::vector<std::function<void()>> callbacks_;
  std::function<void(std::chrono::milliseconds)> wait_observer_;
};

// Blocks SIGTERM and SIGINT in the calling thread (and so in every thread it
// starts later) and starts a thread that calls stop->Stop() when one arrives.
// Call it before starting any other thread; `stop` must outlive the process.
void StopOnTerminationSignals(StopSignal* stop);

}  // namespace mbopt::worker
