#include "client/interrupts.h"

#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <mutex>
#include <thread>

namespace mbopt::client {
namespace {

std::atomic<bool> g_interrupted{false};
std::mutex g_mutex;
grpc::ClientContext* g_target = nullptr;  // guarded by g_mutex

sigset_t TerminationSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

}  // namespace

void Interrupts::Install() {
  static std::once_flag once;
  std::call_once(once, [] {
    sigset_t set = TerminationSignals();
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread([set] {
      while (true) {
        int sig = 0;
        if (sigwait(&set, &sig) != 0) continue;
        g_interrupted = true;
        std::lock_guard<std::mutex> lock(g_mutex);
        if (g_target != nullptr) g_target->TryCancel();
      }
    }).detach();
  });
}

bool Interrupts::interrupted() { return g_interrupted.load(); }

void Interrupts::SetCancelTarget(grpc::ClientContext* context) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_target = context;
  if (context != nullptr && g_interrupted) context->TryCancel();
}

}  // namespace mbopt::client
