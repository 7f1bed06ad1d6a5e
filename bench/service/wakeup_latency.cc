// The floor under every hand-over between two processes on this machine:
// the round trip of one byte between a parent and a child over two pipes,
// each side blocked in read() until the other writes (a wake-up each way,
// as a gRPC call needs at least two). Prints percentiles of N round trips,
// the processes left to the scheduler and then both pinned to CPU 0: on a
// virtual machine, waking a thread on another (idle) CPU costs an
// inter-processor interrupt and often a VM exit, where a wake-up on the
// same CPU costs a context switch (docs/benchmarks.md, "Service").
//
//   build/bench/service/bench_wakeup_latency [N]
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

// Round trips in microseconds, sorted; the child answers each byte.
std::vector<double> PingPong(int n, bool same_cpu) {
  int to_child[2];
  int to_parent[2];
  if (pipe(to_child) != 0 || pipe(to_parent) != 0) {
    std::perror("pipe");
    std::exit(1);
  }
  if (same_cpu) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    CPU_SET(0, &cpus);
    if (sched_setaffinity(0, sizeof cpus, &cpus) != 0) std::perror("sched_setaffinity");
  }
  const pid_t child = fork();
  if (child == 0) {
    char byte = 0;
    for (int i = 0; i < n; ++i) {
      if (read(to_child[0], &byte, 1) != 1 || write(to_parent[1], &byte, 1) != 1) _exit(1);
    }
    _exit(0);
  }
  std::vector<double> us;
  us.reserve(static_cast<size_t>(n));
  char byte = 'x';
  for (int i = 0; i < n; ++i) {
    const auto start = std::chrono::steady_clock::now();
    if (write(to_child[1], &byte, 1) != 1 || read(to_parent[0], &byte, 1) != 1) {
      std::perror("ping-pong");
      std::exit(1);
    }
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
  }
  waitpid(child, nullptr, 0);
  for (int fd : {to_child[0], to_child[1], to_parent[0], to_parent[1]}) close(fd);
  std::sort(us.begin(), us.end());
  return us;
}

void Print(const char* what, const std::vector<double>& us) {
  auto at = [&](double p) { return us[std::min(us.size() - 1, static_cast<size_t>(p * static_cast<double>(us.size())))]; };
  std::printf("%-22s p50 %7.1f us   p90 %7.1f us   p99 %7.1f us\n", what, at(0.50), at(0.90), at(0.99));
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::max(100, std::atoi(argv[1])) : 5000;
  std::printf("pipe round trips between two processes, %d each:\n", n);
  Print("scheduler's choice", PingPong(n, false));
  Print("both on CPU 0", PingPong(n, true));  // last: it pins this process
  return 0;
}
