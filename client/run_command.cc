// `mbopt run`: the embedded default. Server, workers, submission, watch and
// result in one command; everything it started is stopped on the way out,
// also after Ctrl-C. The job database is kept (DefaultRunDatabasePath) so that
// `report`, `results` and `resume` can read it with --db afterwards.
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/args.h"
#include "client/commands.h"
#include "client/connection.h"
#include "client/design_set_format.h"
#include "client/pareto_format.h"
#include "client/exit_codes.h"
#include "client/interrupts.h"
#include "client/job_format.h"
#include "client/local_cluster.h"
#include "client/local_worker_drivers.h"
#include "client/study_file.h"
#include "client/subprocess.h"
#include "client/temp_dir.h"
#include "client/watch.h"

namespace mbopt::client {
namespace {

// Where `mbopt run` keeps its job database unless --db or --discard-db says
// otherwise: $XDG_STATE_HOME/mbopt/runs (default ~/.local/state/mbopt/runs),
// one file per run named after the study file and the UTC start time. Empty
// when neither variable gives a directory that can be made.
std::string DefaultRunDatabasePath(const std::string& study_path) {
  std::filesystem::path base;
  if (const char* state = std::getenv("XDG_STATE_HOME"); state != nullptr && *state == '/') {
    base = state;
  } else if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/') {
    base = std::filesystem::path(home) / ".local" / "state";
  } else {
    return "";
  }
  const std::filesystem::path dir = base / "mbopt" / "runs";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return "";
  // Job databases hold the study and every result: not for other users.
  std::filesystem::permissions(dir, std::filesystem::perms::owner_all, ec);
  std::string stem = std::filesystem::path(study_path).filename().string();
  for (const char* suffix : {".textproto", ".json", ".study"}) {
    if (stem.size() > std::strlen(suffix) && stem.ends_with(suffix)) stem.resize(stem.size() - std::strlen(suffix));
  }
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
  return (dir / (stem + "-" + stamp + "-" + std::to_string(getpid()) + ".db")).string();
}

// Waits until `count` workers have registered with the local server (a
// failure guard of 60 s: a worker that cannot start says why in its log).
absl::Status WaitForWorkers(v1::JobService::Stub& job_service, int count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (true) {
    v1::ListWorkersResponse workers;
    grpc::ClientContext context;
    SetUnaryDeadline(&context);
    grpc::Status status = job_service.ListWorkers(&context, v1::ListWorkersRequest(), &workers);
    if (status.ok() && workers.workers_size() >= count) return absl::OkStatus();
    if (std::chrono::steady_clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrCat("mbopt run: ", status.ok() ? workers.workers_size() : 0, " of ",
                                                      count, " local workers registered within 60 s"));
    }
    // Workers register within milliseconds of starting; polling is cheaper
    // than a notification the server does not offer.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

int RunCommandMain(const Args& args) {
  auto parsed =
      ParseArgs(args, {{"--workers", "--db", "--drivers"}, {"--json", "--quiet", "--discard-db", "--keep-runs"}});
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  if (parsed->positional.size() != 1) {
    return Fail("usage: mbopt run STUDY_FILE [--workers N] [--db PATH | --discard-db] [--json] [--quiet]\n"
                "                 [--drivers FILE [--keep-runs]]",
                kExitBadInput);
  }
  if (!parsed->Value("--db").empty() && parsed->Has("--discard-db")) {
    return Fail("--db and --discard-db exclude each other", kExitBadInput);
  }
  auto workers = parsed->IntValue("--workers", 1);
  if (!workers.ok()) return Fail(std::string(workers.status().message()), kExitBadInput);
  const int num_workers = workers->value_or(
      std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  const bool json = parsed->Has("--json");
  const bool quiet = parsed->Has("--quiet");
  const std::string path = parsed->positional[0];

  // Bad input is reported before anything is started.
  auto study = ReadStudyForSubmission(path);
  if (!study.ok()) return Fail(std::string(study.status().message()), kExitBadInput);
  auto server_binary = FindMboptBinary("mbopt-server", "MBOPT_SERVER_BIN", "server/main");
  if (!server_binary.ok()) return Fail(std::string(server_binary.status().message()), kExitBadInput);
  auto worker_binary = FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
  if (!worker_binary.ok()) return Fail(std::string(worker_binary.status().message()), kExitBadInput);
  auto worker_args = LocalWorkerDriverArgs(*parsed, *worker_binary);
  if (!worker_args.ok()) return Fail(std::string(worker_args.status().message()), kExitBadInput);

  Interrupts::Install();  // before any thread (gRPC's included) is started
  TempDir temp;
  if (temp.path().empty()) return Fail("cannot create a temporary directory", kExitBadInput);
  LocalClusterOptions cluster_options;
  cluster_options.server_binary = *server_binary;
  cluster_options.worker_binary = *worker_binary;
  std::string db_path = parsed->Value("--db");
  if (db_path.empty() && !parsed->Has("--discard-db")) {
    db_path = DefaultRunDatabasePath(path);
    if (db_path.empty()) {
      std::fprintf(stderr,
                   "mbopt run: cannot make $XDG_STATE_HOME/mbopt/runs or ~/.local/state/mbopt/runs; the job "
                   "database is temporary this time (--db PATH keeps it elsewhere)\n");
    }
  }
  const bool keep_db = !db_path.empty();
  if (!keep_db) db_path = temp.path() + "/mbopt.db";
  cluster_options.db_path = db_path;
  cluster_options.log_dir = temp.path();
  cluster_options.workers = num_workers;
  cluster_options.worker_args = *std::move(worker_args);
  auto cluster = LocalCluster::Start(cluster_options);
  if (!cluster.ok()) return Fail(std::string(cluster.status().message()), kExitUnreachable);
  const std::string address = (*cluster)->address();
  if (!quiet && !json) {
    std::printf("mbopt run: server at %s, %d workers\n", address.c_str(), num_workers);
  }

  auto job_service = ConnectJobService(address);
  if (!cluster_options.worker_args.empty()) {
    // The server refuses a study naming a driver no registered worker
    // declares: submit once the local workers have registered theirs.
    if (absl::Status registered = WaitForWorkers(*job_service, num_workers); !registered.ok()) {
      return Fail(std::string(registered.message()), kExitUnreachable);
    }
  }
  v1::SubmitJobRequest request;
  request.set_study(study->SerializeAsString());
  request.set_source_name(path);
  v1::SubmitJobResponse submitted;
  {
    grpc::ClientContext context;
    SetUnaryDeadline(&context);
    grpc::Status status = job_service->Submit(&context, request, &submitted);
    if (!status.ok()) {
      RpcFailure f = DescribeRpcFailure(status, address);
      return Fail(f.message, f.exit_code);
    }
  }
  const std::string job_id = submitted.job_id();
  if (!quiet && !json) std::printf("job %s\n", job_id.c_str());

  WatchOptions watch_options;
  watch_options.table_out = (quiet || json) ? nullptr : stdout;
  watch_options.progress_line = watch_options.table_out != nullptr && isatty(STDOUT_FILENO);
  watch_options.study = &*study;
  WatchOutcome outcome = WatchJob(*job_service, address, job_id, watch_options);

  v1::GetJobResponse job;
  const grpc::Status get_status = GetJob(*job_service, job_id, &job);
  // Close our connection first: a server that is stopping waits out its
  // grace period (server/service/server.cc) for clients still connected.
  job_service.reset();
  (*cluster)->Stop();

  if (outcome.interrupted) {
    if (keep_db) {
      std::fprintf(stderr,
                   "mbopt run: interrupted; server and workers stopped; continue with\n"
                   "  mbopt resume %s --db %s%s\n",
                   job_id.c_str(), db_path.c_str(), DriverArgsText(cluster_options.worker_args).c_str());
    } else {
      std::fprintf(stderr, "mbopt run: interrupted; server and workers stopped, temporary database removed\n");
    }
    if (json && get_status.ok()) {
      job.mutable_summary()->set_state(v1::JOB_STATE_INTERRUPTED);
      std::fputs(ResultsJson(job, keep_db ? db_path : "").c_str(), stdout);
    }
    return kExitInterrupted;
  }
  if (!outcome.ok) return Fail(outcome.failure.message, outcome.failure.exit_code);
  if (!get_status.ok()) {
    RpcFailure f = DescribeRpcFailure(get_status, address);
    return Fail(f.message, f.exit_code);
  }
  if (json) {
    std::fputs(ResultsJson(job, keep_db ? db_path : "").c_str(), stdout);
  } else if (!quiet) {
    // A design set's table is its result: every design with its values.
    // A Pareto front's table is its points.
    std::printf("\n%s", IsParetoJob(job)      ? ParetoTable(job).c_str()
                       : IsDesignSetJob(job) ? DesignSetTable(job).c_str()
                                             : SummaryText(job.summary(), job.has_study() ? &job.study() : nullptr).c_str());
    if (keep_db) {
      std::printf("database:      %s\n"
                  "report:        mbopt report %s --db %s\n",
                  db_path.c_str(), job_id.c_str(), db_path.c_str());
    }
  }
  return ExitCodeForState(job.summary().state());
}

}  // namespace mbopt::client
