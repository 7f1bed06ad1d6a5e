#include "client/commands.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <variant>

#include "client/args.h"
#include "client/connection.h"
#include "client/design_set_format.h"
#include "client/pareto_format.h"
#include "client/pareto_report_from_job.h"
#include "client/design_set_report_from_job.h"
#include "client/exit_codes.h"
#include "client/interrupts.h"
#include "client/job_format.h"
#include "client/local_cluster.h"
#include "client/local_worker_drivers.h"
#include "client/report/deflection_scale.h"
#include "client/report/design_set_report.h"
#include "client/report/pareto_report.h"
#include "client/report/job_report_html.h"
#include "client/report/report_from_proto.h"
#include "client/report_mechanism.h"
#include "client/report_responses.h"
#include "client/study_file.h"
#include "client/temp_dir.h"
#include "client/watch.h"

namespace mbopt::client {
namespace {

// Every command that reads a job takes --server, or --db: the database a
// finished `mbopt run` kept, served by a private server for this command.
const ArgSpec kServerOrDb{{"--server", "--db"}, {}};

// Parses `args`, requiring exactly `positional` positional arguments.
absl::StatusOr<ParsedArgs> Parse(const Args& args, const ArgSpec& spec, size_t positional,
                                 const char* usage) {
  ArgSpec with_security = spec;
  if (spec.value_options.count("--server") > 0) {
    for (const char* option : secure_channel::kSecurityValueOptions) with_security.value_options.insert(option);
  }
  auto parsed = ParseArgs(args, with_security);
  if (!parsed.ok()) return parsed.status();
  if (parsed->positional.size() != positional) {
    return absl::InvalidArgumentError(std::string("usage: ") + usage);
  }
  return parsed;
}

struct Connection {
  // Declared first so that they go last: the client closes its channel
  // before the private server stops, and that before its directory goes.
  std::unique_ptr<TempDir> temp_dir;
  std::unique_ptr<LocalCluster> local;
  std::string address;
  secure_channel::ClientSecurity security;  // plaintext for the private server
  std::unique_ptr<v1::JobService::Stub> job_service;  // the gRPC client of the server's JobService
};

struct ConnectFailure {
  std::string message;
  int exit_code = kExitBadInput;
};

// The server of --server, or with --db PATH a private one on 127.0.0.1 on
// that database, with `workers` local workers (0: it only answers) started
// with `worker_args`.
std::variant<Connection, ConnectFailure> Connect(const ParsedArgs& parsed, int workers = 0,
                                                 std::vector<std::string> worker_args = {}) {
  Connection c;
  const std::string db = parsed.Value("--db");
  if (db.empty()) {
    c.address = ResolveServerAddress(parsed.Value("--server"));
    secure_channel::ClientSecurityFlags flags;
    for (const char* option : secure_channel::kSecurityValueOptions) {
      secure_channel::SetSecurityFlag(option, parsed.Value(option), &flags);
    }
    absl::StatusOr<secure_channel::ClientSecurity> security = secure_channel::LoadClientSecurity(flags);
    if (!security.ok()) return ConnectFailure{std::string(security.status().message())};
    c.security = *std::move(security);
    c.job_service = ConnectJobService(c.address, c.security);
    return c;
  }
  if (!parsed.Value("--server").empty()) return ConnectFailure{"--db and --server exclude each other"};
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db, ec)) {
    return ConnectFailure{"no job database at " + db + " (--db names the file that `mbopt run` printed)"};
  }
  auto server_binary = FindMboptBinary("mbopt-server", "MBOPT_SERVER_BIN", "server/main");
  if (!server_binary.ok()) return ConnectFailure{std::string(server_binary.status().message())};
  auto worker_binary = FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
  if (!worker_binary.ok()) return ConnectFailure{std::string(worker_binary.status().message())};
  Interrupts::Install();  // before the cluster's and gRPC's threads
  c.temp_dir = std::make_unique<TempDir>();
  if (c.temp_dir->path().empty()) return ConnectFailure{"cannot create a temporary directory"};
  LocalClusterOptions options;
  options.server_binary = *server_binary;
  options.worker_binary = *worker_binary;
  options.db_path = db;
  options.log_dir = c.temp_dir->path();
  options.workers = workers;
  options.worker_args = std::move(worker_args);
  // Without workers the private server is there to show the jobs: it must
  // not resume one (nothing would analyse it) nor call it running.
  options.inspect_only = workers == 0;
  auto cluster = LocalCluster::Start(options);
  if (!cluster.ok()) return ConnectFailure{std::string(cluster.status().message()), kExitUnreachable};
  c.local = *std::move(cluster);
  c.address = c.local->address();
  c.job_service = ConnectJobService(c.address);
  return c;
}

int FailRpc(const grpc::Status& status, const std::string& address,
            const secure_channel::ClientSecurity* security = nullptr) {
  RpcFailure f = DescribeRpcFailure(status, address, security);
  return Fail(f.message, f.exit_code);
}

// One job with its cycle history and study, as the server keeps it.
grpc::Status GetJob(Connection& c, const std::string& job_id, v1::GetJobResponse* response) {
  return client::GetJob(*c.job_service, job_id, response);
}

// Follows a job to its end, printing the table; returns the exit code of its
// final state.
// Interrupts::Install() must have been called before the connection was made.
int Follow(Connection& c, const std::string& job_id) {
  WatchOptions options;
  options.progress_line = isatty(STDOUT_FILENO) != 0;
  WatchOutcome outcome = WatchJob(*c.job_service, c.address, job_id, options);
  if (outcome.interrupted) {
    std::fprintf(stderr, "mbopt: stopped watching; job %s goes on on the server\n",
                 job_id.c_str());
    return kExitInterrupted;
  }
  if (!outcome.ok) return Fail(outcome.failure.message, outcome.failure.exit_code);
  const auto& s = outcome.summary;
  std::fputs(WatchEndLine(job_id, s).c_str(), stdout);
  if (!s.message().empty()) std::printf("%s\n", s.message().c_str());
  return ExitCodeForState(s.state());
}

}  // namespace

int Fail(const std::string& message, int exit_code) {
  std::fprintf(stderr, "mbopt: %s\n", message.c_str());
  return exit_code;
}

int SubmitCommand(const Args& args) {
  auto parsed = Parse(args, {{"--server"}, {"--watch"}}, 1,
                      "mbopt submit STUDY_FILE [--watch] [--server ADDRESS]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  const std::string path = parsed->positional[0];
  auto study = ReadStudyForSubmission(path);
  if (!study.ok()) return Fail(std::string(study.status().message()), kExitBadInput);
  if (parsed->Has("--watch")) Interrupts::Install();  // before gRPC starts threads
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::SubmitJobRequest request;
  request.set_study(study->SerializeAsString());
  request.set_source_name(path);
  v1::SubmitJobResponse response;
  grpc::ClientContext context;
  SetUnaryDeadline(&context);
  grpc::Status status = c.job_service->Submit(&context, request, &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  std::printf("%s\n", response.job_id().c_str());
  std::fflush(stdout);
  if (!parsed->Has("--watch")) return kExitOk;
  return Follow(c, response.job_id());
}

int WatchCommand(const Args& args) {
  auto parsed = Parse(args, kServerOrDb, 1, "mbopt watch JOB [--server ADDRESS | --db PATH]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  Interrupts::Install();  // before gRPC starts threads
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  return Follow(c, parsed->positional[0]);
}

int StatusCommand(const Args& args) {
  auto parsed = Parse(args, kServerOrDb, 1, "mbopt status JOB [--server ADDRESS | --db PATH]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::GetJobResponse response;
  grpc::Status status = GetJob(c, parsed->positional[0], &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  std::fputs(SummaryText(response.summary(), response.has_study() ? &response.study() : nullptr).c_str(), stdout);
  return kExitOk;
}

int ListCommand(const Args& args) {
  auto parsed = Parse(args, kServerOrDb, 0, "mbopt list [--server ADDRESS | --db PATH]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::ListJobsResponse response;
  grpc::ClientContext context;
  SetUnaryDeadline(&context);
  grpc::Status status = c.job_service->List(&context, v1::ListJobsRequest(), &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  std::printf("%s\n", ListHeader().c_str());
  for (const auto& job : response.jobs()) std::printf("%s\n", ListRow(job).c_str());
  return kExitOk;
}

int WorkersCommand(const Args& args) {
  auto parsed = Parse(args, {{"--server"}, {}}, 0, "mbopt workers [--server ADDRESS]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::ListWorkersResponse response;
  grpc::ClientContext context;
  SetUnaryDeadline(&context);
  grpc::Status status = c.job_service->ListWorkers(&context, v1::ListWorkersRequest(), &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  std::printf("%s\n", WorkersHeader().c_str());
  for (const auto& worker : response.workers()) std::printf("%s\n", WorkersRow(worker).c_str());
  return kExitOk;
}

namespace {

int CancelOrResume(const ParsedArgs& parsed, bool cancel, int workers,
                   std::vector<std::string> worker_args = {}) {
  auto connected = Connect(parsed, workers, std::move(worker_args));
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  const std::string job_id = parsed.positional[0];
  if (!cancel && c.local == nullptr) {
    // The server answers a resume of a live job with its summary and does
    // nothing; say so, rather than print a state that looks like a resume.
    v1::GetJobResponse current;
    grpc::Status got = GetJob(c, job_id, &current);
    if (!got.ok()) return FailRpc(got, c.address, &c.security);
    const v1::JobState state = current.summary().state();
    if (state == v1::JOB_STATE_RUNNING || state == v1::JOB_STATE_QUEUED) {
      std::printf("%s: %s already; nothing to resume (`mbopt watch %s` follows it)\n", job_id.c_str(),
                  StateName(state).c_str(), job_id.c_str());
      return kExitOk;
    }
  }
  v1::JobRef ref;
  ref.set_job_id(job_id);
  v1::JobSummary summary;
  grpc::ClientContext context;
  SetUnaryDeadline(&context);
  grpc::Status status = cancel ? c.job_service->Cancel(&context, ref, &summary)
                               : c.job_service->Resume(&context, ref, &summary);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  std::printf("%s: %s\n", summary.job_id().c_str(), StateName(summary.state()).c_str());
  std::fflush(stdout);
  // A private server stops with this command: stay until the job ends.
  if (c.local != nullptr && !cancel) return Follow(c, job_id);
  return kExitOk;
}

}  // namespace

int CancelCommand(const Args& args) {
  auto parsed = Parse(args, {{"--server"}, {}}, 1, "mbopt cancel JOB [--server ADDRESS]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  return CancelOrResume(*parsed, true, 0);
}

int ResumeCommand(const Args& args) {
  auto parsed = Parse(args, {{"--server", "--db", "--workers", "--drivers"}, {"--keep-runs"}}, 1,
                      "mbopt resume JOB [--server ADDRESS | --db PATH [--workers N] [--drivers FILE [--keep-runs]]]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  auto workers = parsed->IntValue("--workers", 1);
  if (!workers.ok()) return Fail(std::string(workers.status().message()), kExitBadInput);
  const bool local_workers_options = workers->has_value() || !parsed->Value("--drivers").empty() || parsed->Has("--keep-runs");
  if (local_workers_options && parsed->Value("--db").empty()) {
    return Fail("--workers, --drivers and --keep-runs need --db (a server's own workers are started with "
                "mbopt-worker)",
                kExitBadInput);
  }
  std::vector<std::string> worker_args;
  if (!parsed->Value("--db").empty()) {
    auto worker_binary = FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
    if (!worker_binary.ok()) return Fail(std::string(worker_binary.status().message()), kExitBadInput);
    auto driver_args = LocalWorkerDriverArgs(*parsed, *worker_binary);
    if (!driver_args.ok()) return Fail(std::string(driver_args.status().message()), kExitBadInput);
    worker_args = *std::move(driver_args);
  }
  return CancelOrResume(*parsed, false,
                        workers->value_or(std::max(1, static_cast<int>(std::thread::hardware_concurrency()))),
                        std::move(worker_args));
}

int ResultsCommand(const Args& args) {
  auto parsed = Parse(args, {{"--server", "--db", "--point"}, {"--csv", "--json"}}, 1,
                      "mbopt results JOB [--csv | --json | --point K [--json]] [--server ADDRESS | --db PATH]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  if (parsed->Has("--csv") && parsed->Has("--json")) {
    return Fail("--csv and --json exclude each other", kExitBadInput);
  }
  auto point = parsed->IntValue("--point", 1);
  if (!point.ok()) return Fail(std::string(point.status().message()), kExitBadInput);
  if (point->has_value() && parsed->Has("--csv")) {
    return Fail("--point shows one point: as text, or with --json; --csv lists them all", kExitBadInput);
  }
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::GetJobResponse response;
  grpc::Status status = GetJob(c, parsed->positional[0], &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  if (point->has_value()) {
    if (!IsParetoJob(response)) {
      return Fail("--point picks a point of a Pareto front; job " + parsed->positional[0] + " is not one",
                  kExitBadInput);
    }
    absl::StatusOr<std::string> shown = parsed->Has("--json") ? ParetoPointJson(response, **point)
                                                              : ParetoPointText(response, **point);
    if (!shown.ok()) return Fail(std::string(shown.status().message()), kExitBadInput);
    std::fputs(shown->c_str(), stdout);
    return ExitCodeForState(response.summary().state());
  }
  if (parsed->Has("--json")) {
    std::fputs(ResultsJson(response).c_str(), stdout);
  } else if (parsed->Has("--csv")) {
    std::fputs(ResultsCsv(response).c_str(), stdout);
  } else {
    std::fputs(ResultsTable(response).c_str(), stdout);
  }
  return ExitCodeForState(response.summary().state());
}

namespace {

// Writes a report page to `path` and says where.
int WriteReport(const std::string& path, const std::string& html) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << html;
  out.close();
  if (!out) return Fail("cannot write the report to " + path, kExitBadInput);
  std::printf("wrote %s\n", path.c_str());
  return kExitOk;
}

}  // namespace

int ReportCommand(const Args& args) {
  // `-o` is the one short option mbopt takes: the usual spelling for an output file.
  // --plot is repeatable, which the option parser's one value per name is
  // not: taken out first.
  Args spelled;
  std::vector<std::string> plots;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--plot" && i + 1 < args.size()) {
      plots.push_back(args[++i]);
    } else if (args[i].rfind("--plot=", 0) == 0) {
      plots.push_back(args[i].substr(7));
    } else {
      spelled.push_back(args[i] == "-o" ? "--output" : args[i]);
    }
  }
  auto parsed = Parse(spelled,
                      {{"--server", "--db", "--output", "--plot", "--point", "--deflection-scale"},
                       {"--no-responses", "--no-mechanism"}},
                      1,
                      "mbopt report JOB [-o|--output FILE] [--server ADDRESS | --db PATH] [--no-responses] "
                      "[--no-mechanism] [--plot X:Y ...] [--point K (a Pareto front's chosen point)] "
                      "[--deflection-scale K]");
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  double deflection_scale = 1.0;
  if (const std::string scale = parsed->Value("--deflection-scale");
      !scale.empty() && !report::ParseDeflectionScale(scale, &deflection_scale)) {
    return Fail("--deflection-scale needs a positive number, not \"" + scale + "\"", kExitBadInput);
  }
  auto point = parsed->IntValue("--point", 1);
  if (!point.ok()) return Fail(std::string(point.status().message()), kExitBadInput);
  const std::string job_id = parsed->positional[0];
  std::string path = parsed->Value("--output");
  if (path.empty()) path = job_id + ".html";
  auto connected = Connect(*parsed);
  if (auto* f = std::get_if<ConnectFailure>(&connected)) return Fail(f->message, f->exit_code);
  Connection& c = std::get<Connection>(connected);
  v1::GetJobResponse response;
  grpc::Status status = GetJob(c, job_id, &response);
  if (!status.ok()) return FailRpc(status, c.address, &c.security);
  if (IsParetoJob(response)) {
    // A front's page draws its points; --point marks the one picked.
    if (point->has_value()) {
      if (absl::StatusOr<std::string> found = ParetoPointText(response, **point); !found.ok()) {
        return Fail(std::string(found.status().message()), kExitBadInput);
      }
    }
    report::ParetoReportData front = ParetoReportFromJob(response, point->value_or(0));
    if (front.chosen != 0) {
      if (parsed->Has("--no-responses")) {
        front.chosen_responses_note = "Not analysed (mbopt report --no-responses).";
      } else {
        AddChosenPointResponses(response, &front);
      }
    }
    return WriteReport(path, report::RenderParetoReportHtml(front));
  }
  if (point->has_value()) {
    return Fail("--point picks a point of a Pareto front; job " + job_id + " is not one", kExitBadInput);
  }
  if (IsDesignSetJob(response)) {
    // A sweep or sample has no optimization history: its page plots the
    // objective and constraints against the design.
    return WriteReport(path, report::RenderDesignSetReportHtml(DesignSetReportFromJob(response)));
  }
  report::ReportData data = report::ReportDataFromJob(response);
  if (parsed->Has("--no-responses")) {
    if (!plots.empty()) return Fail("--plot needs the analyses that --no-responses leaves out", kExitBadInput);
    data.responses_note = "Not analysed (mbopt report --no-responses).";
    SetViolationTolerance(response, &data);
  } else if (absl::Status added = AddResponsePlots(response, plots, &data); !added.ok()) {
    return Fail(std::string(added.message()), kExitBadInput);
  }
  if (parsed->Has("--no-mechanism")) {
    data.mechanism.note = "Not drawn (mbopt report --no-mechanism).";
  } else {
    AddMechanismDrawings(response, &data, deflection_scale);
  }
  return WriteReport(path, report::RenderJobReportHtml(data));
}

}  // namespace mbopt::client
