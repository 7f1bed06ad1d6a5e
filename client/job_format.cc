#include "client/job_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/design_set_format.h"
#include "client/pareto_format.h"
#include "client/exit_codes.h"
#include "client/json_writer.h"
#include "client/report/report_from_proto.h"

namespace mbopt::client {
namespace {

std::string Format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::vector<double> ToVector(const google::protobuf::RepeatedField<double>& values) {
  return std::vector<double>(values.begin(), values.end());
}

// Min and max of the move limits of one LP.
std::pair<double, double> MinMax(const google::protobuf::RepeatedField<double>& values) {
  if (values.empty()) return {NAN, NAN};
  auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  return {*lo, *hi};
}

// The study's variable of that name, or null (a job without its study).
const v1::DesignVariable* FindVariable(const v1::Study* study, const std::string& name) {
  if (study == nullptr) return nullptr;
  for (const auto& v : study->variables()) {
    if (v.name() == name) return &v;
  }
  return nullptr;
}

double ScaleOf(const v1::DesignVariable& v) { return v.scale() == 0 ? 1.0 : v.scale(); }

// One line per variable. The summary's values are physical (the parameter's
// value); the variable itself is scaled, so a line names both, e.g.
// "x1 = 5  (k1 = 50 lbf/in)", and never puts a variable's name beside the
// parameter's value alone.
std::string DesignLines(const v1::JobSummary& s, const v1::Study* study) {
  std::string out;
  for (int i = 0; i < s.design_names_size() && i < s.design_size(); ++i) {
    const std::string unit = i < s.design_units_size() ? s.design_units(i) : "";
    const std::string physical = Format("%.8g", s.design(i)) + (unit.empty() ? "" : " " + unit);
    char buf[512];
    if (const v1::DesignVariable* v = FindVariable(study, s.design_names(i))) {
      const std::string scaled = Format("%.8g", s.design(i) / ScaleOf(*v));
      std::snprintf(buf, sizeof buf, "  %s = %s  (%s = %s)\n", s.design_names(i).c_str(),
                    scaled.c_str(), v->parameter().c_str(), physical.c_str());
    } else {
      std::snprintf(buf, sizeof buf, "  %s sets its parameter to %s\n", s.design_names(i).c_str(),
                    physical.c_str());
    }
    out += buf;
  }
  return out;
}

}  // namespace

std::string StateName(v1::JobState state) { return report::JobStateName(state); }

bool IsTerminal(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_CONVERGED:
    case v1::JOB_STATE_COMPLETED:
    case v1::JOB_STATE_MAX_CYCLES:
    case v1::JOB_STATE_STALLED:
    case v1::JOB_STATE_FAILED:
    case v1::JOB_STATE_CANCELLED:
    case v1::JOB_STATE_INTERRUPTED:
      return true;
    default:
      return false;
  }
}

int ExitCodeForState(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_CONVERGED: return kExitOk;
    case v1::JOB_STATE_COMPLETED: return kExitOk;
    case v1::JOB_STATE_FAILED: return kExitJobFailed;
    case v1::JOB_STATE_QUEUED:
    case v1::JOB_STATE_RUNNING: return kExitOk;
    default: return kExitNotConverged;
  }
}

std::string CycleTableHeader() {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%5s %3s %14s %10s %10s %9s %4s %4s %9s %9s %9s", "cycle",
                "att", "F", "maxg", "maxfout", "kkt", "feas", "acc", "ml_min", "ml_max", "analyses");
  return buf;
}

std::string CycleTableRow(const v1::CycleRecord& r) {
  auto [ml_min, ml_max] = MinMax(r.move_limits());
  char buf[256];
  // A restoration step shows as "r" and its attempt: it belongs to the
  // cycle that converged.
  const std::string attempt = (r.restoration() ? "r" : "") + std::to_string(r.attempt());
  std::snprintf(buf, sizeof buf, "%5d %3s %14.7g %10.4g %10.4g %9.3g %4s %4s %9.3g %9.3g %9lld",
                r.cycle(), attempt.c_str(), r.objective_trial(), r.max_violation_trial(),
                r.max_approximation_error(), r.optimality_residual(), r.lp_feasible() ? "yes" : "no",
                r.accepted() ? "yes" : "no", ml_min, ml_max,
                static_cast<long long>(r.analyses_total()));
  return buf;
}

// "3 analyses (integrator 2, assembly 1)", kinds in name order.
std::string FailedAnalysesText(const v1::JobSummary& s) {
  const std::map<std::string, std::int64_t> failed(s.failed_analyses_by_kind().begin(),
                                                   s.failed_analyses_by_kind().end());
  std::int64_t total = 0;
  std::string kinds;
  for (const auto& [kind, count] : failed) {
    total += count;
    kinds += (kinds.empty() ? "" : ", ") + kind + " " + std::to_string(count);
  }
  return std::to_string(total) + (total == 1 ? " analysis (" : " analyses (") + kinds + ")";
}

std::string SummaryText(const v1::JobSummary& s, const v1::Study* study) {
  std::string out;
  out += "job:           " + s.job_id() + "\n";
  out += "study:         " + s.study_name() + "\n";
  if (!s.owner().empty()) out += "submitted by:  " + s.owner() + "\n";
  out += "status:        " + StateName(s.state()) + "\n";
  if (s.pareto()) {
    out += "points:        " + std::to_string(s.cycles()) + " of " + std::to_string(s.max_cycles()) +
           " on the Pareto front computed\n";
  } else if (s.design_set()) {
    out += "designs:       " + std::to_string(s.cycles()) + " of " + std::to_string(s.max_cycles()) + " analysed\n";
  } else {
    out += "cycles:        " + std::to_string(s.cycles()) +
           (s.max_cycles() > 0 ? " (of at most " + std::to_string(s.max_cycles()) + ")" : "") + "\n";
  }
  out += "analyses:      " + std::to_string(s.analyses()) + "\n";
  if (std::isfinite(s.objective())) {
    out += "objective:     " + Format("%.10g", s.objective()) +
           (s.objective_unit().empty() ? "" : " " + s.objective_unit()) + "\n";
    out += "max violation: " + Format("%.4g", s.max_violation()) + "\n";
  } else {
    out += "objective:     none (no design was analysed)\n";
  }
  out += "wall time:     " + Format("%.2f", s.wall_seconds()) + " s\n";
  if (!s.message().empty()) out += "message:       " + s.message() + "\n";
  if (!s.waiting_for().empty()) out += "waiting:       " + s.waiting_for() + "\n";
  if (!s.failed_analyses_by_kind().empty()) out += "failed:        " + FailedAnalysesText(s) + "\n";
  // A design set's summary design is its best analysed design.
  if (s.design_size() > 0) out += (s.design_set() ? "best design:\n" : "design:\n") + DesignLines(s, study);
  return out;
}

std::string ListHeader() {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-24s %-24s %-12s %6s %9s %14s  %s", "JOB", "STUDY", "STATUS",
                "CYCLES", "ANALYSES", "OBJECTIVE", "OWNER");
  return buf;
}

std::string WatchEndLine(const std::string& job_id, const v1::JobSummary& s) {
  if (s.pareto()) {
    // A front has no one F: each point has its own, listed by `results`.
    return absl::StrFormat("%s: %s after %d of %d points, %d analyses; `mbopt results %s` lists the front\n", job_id,
                           StateName(s.state()), s.cycles(), s.max_cycles(), s.analyses(), job_id);
  }
  std::string out = absl::StrFormat("%s: %s after %d %s, %d analyses", job_id, StateName(s.state()), s.cycles(),
                                    s.design_set() ? "designs" : "cycles", s.analyses());
  if (std::isfinite(s.objective())) {
    out += absl::StrFormat(", F = %.10g %s, max violation %.4g\n", s.objective(), s.objective_unit(),
                           s.max_violation());
  } else {
    out += ", no design analysed\n";
  }
  return out;
}

std::string ListRow(const v1::JobSummary& s) {
  char buf[512];
  const std::string objective = std::isfinite(s.objective()) ? Format("%.7g", s.objective()) : "-";
  // OWNER: who submitted it, "-" on a server without tokens.
  std::snprintf(buf, sizeof buf, "%-24s %-24s %-12s %6d %9lld %14s  %s", s.job_id().c_str(),
                s.study_name().c_str(), StateName(s.state()).c_str(), s.cycles(),
                static_cast<long long>(s.analyses()), objective.c_str(),
                s.owner().empty() ? "-" : s.owner().c_str());
  return buf;
}

std::string WorkersHeader() {
  return absl::StrFormat("%-8s %-24s %-16s %5s %9s %5s %8s  %s", "WORKER", "NAME", "TOKEN", "SLOTS", "ANALYSES", "HELD",
                         "SILENT", "CAN RUN");
}

std::string WorkersRow(const v1::WorkerSummary& w) {
  // Built-in scenes run everywhere; the rest is what the worker declared.
  std::string can_run = "built-in scenes";
  for (const std::string& driver : w.drivers()) can_run += ", driver " + driver;
  if (!w.fmu_platform().empty()) can_run += ", FMUs for " + w.fmu_platform();
  // A spot check caught it: it runs nothing until the server restarts.
  if (w.quarantined()) can_run = "QUARANTINED (a spot check caught a wrong result): nothing";
  return absl::StrFormat("%-8s %-24s %-16s %5d %9d %5d %7.1fs  %s", w.id(), w.name(),
                         w.holder().empty() ? "-" : w.holder(), w.slots(), w.analyses_done(), w.tasks_held(),
                         static_cast<double>(w.silent_ms()) / 1000.0, can_run);
}

std::string ComputedByText(const v1::GetJobResponse& job) {
  // Analyses no token delivered (a server without tokens, the server's own
  // failures) are not a machine worth naming.
  std::vector<std::string> parts;
  for (const v1::AnalysesByHolder& count : job.computed_by()) {
    if (count.holder().empty()) continue;
    parts.push_back(absl::StrCat(count.holder(), " (", count.analyses(), count.analyses() == 1 ? " analysis)" : " analyses)"));
  }
  if (parts.empty()) return "";
  return absl::StrCat("computed by:   ", absl::StrJoin(parts, ", "), "\n");
}

std::string ResultsTable(const v1::GetJobResponse& job) {
  if (IsParetoJob(job)) return ParetoTable(job);
  if (IsDesignSetJob(job)) return DesignSetTable(job);
  std::string out = SummaryText(job.summary(), job.has_study() ? &job.study() : nullptr);
  out += ComputedByText(job);
  // Appended piece by piece: GCC 12 at -O3 reports a false -Wrestrict for
  // "\n" + std::string temporaries here.
  out += '\n';
  out += CycleTableHeader();
  out += '\n';
  for (const auto& r : job.cycles()) {
    out += CycleTableRow(r);
    out += '\n';
  }
  return out;
}

std::string ResultsCsv(const v1::GetJobResponse& job) {
  if (IsParetoJob(job)) return ParetoCsv(job);
  if (IsDesignSetJob(job)) return DesignSetCsv(job);
  const auto& s = job.summary();
  std::string out = "cycle,attempt,accepted,objective,max_violation,max_approximation_error,"
                    "optimality_residual,lp_feasible,move_limit_min,move_limit_max,analyses,restoration";
  for (const auto& name : s.design_names()) out += "," + name;
  out += "\n";
  for (const auto& r : job.cycles()) {
    auto [ml_min, ml_max] = MinMax(r.move_limits());
    out += std::to_string(r.cycle()) + "," + std::to_string(r.attempt()) + "," +
           (r.accepted() ? "1" : "0") + "," + JsonWriter::FormatDouble(r.objective_trial()) +
           "," + JsonWriter::FormatDouble(r.max_violation_trial()) + "," +
           JsonWriter::FormatDouble(r.max_approximation_error()) + "," +
           JsonWriter::FormatDouble(r.optimality_residual()) + "," +
           (r.lp_feasible() ? "1" : "0") + "," + JsonWriter::FormatDouble(ml_min) + "," +
           JsonWriter::FormatDouble(ml_max) + "," + std::to_string(r.analyses_total()) + "," +
           (r.restoration() ? "1" : "0");
    for (int i = 0; i < s.design_names_size(); ++i) {
      out += ",";
      if (i < r.x_trial_physical_size()) out += JsonWriter::FormatDouble(r.x_trial_physical(i));
    }
    out += "\n";
  }
  return out;
}

std::string ResultsJson(const v1::GetJobResponse& job, const std::string& database) {
  if (IsParetoJob(job)) return ParetoJson(job, database);
  if (IsDesignSetJob(job)) return DesignSetJson(job, database);
  const auto& s = job.summary();
  JsonWriter w;
  w.BeginObject();
  w.Field("job_id", s.job_id());
  if (!database.empty()) w.Field("database", database);
  w.Field("study", s.study_name());
  w.Field("status", StateName(s.state()));
  w.Field("cycles", s.cycles());
  w.Field("analyses", static_cast<long long>(s.analyses()));
  w.Field("objective", s.objective());
  w.Field("objective_unit", s.objective_unit());
  w.Field("max_violation", s.max_violation());
  if (!ComputedByText(job).empty()) {
    w.Key("computed_by");
    w.BeginObject();
    for (const v1::AnalysesByHolder& count : job.computed_by()) {
      if (!count.holder().empty()) w.Field(count.holder(), static_cast<long long>(count.analyses()));
    }
    w.EndObject();
  }
  w.Key("design");
  w.BeginObject();
  for (int i = 0; i < s.design_names_size() && i < s.design_size(); ++i) {
    w.Field(s.design_names(i), s.design(i));
  }
  w.EndObject();
  // Only variables the study names (a job read without its study has none).
  const v1::Study* study = job.has_study() ? &job.study() : nullptr;
  w.Key("design_scaled");
  w.BeginObject();
  for (int i = 0; i < s.design_names_size() && i < s.design_size(); ++i) {
    if (const v1::DesignVariable* v = FindVariable(study, s.design_names(i))) {
      w.Field(s.design_names(i), s.design(i) / ScaleOf(*v));
    }
  }
  w.EndObject();
  w.Key("design_parameters");
  w.BeginObject();
  for (int i = 0; i < s.design_names_size(); ++i) {
    if (const v1::DesignVariable* v = FindVariable(study, s.design_names(i))) {
      w.Field(s.design_names(i), v->parameter());
    }
  }
  w.EndObject();
  w.Key("design_units");
  w.BeginObject();
  for (int i = 0; i < s.design_names_size() && i < s.design_units_size(); ++i) {
    w.Field(s.design_names(i), s.design_units(i));
  }
  w.EndObject();
  w.Field("wall_seconds", s.wall_seconds());
  w.Field("message", s.message());
  if (!s.waiting_for().empty()) w.Field("waiting_for", s.waiting_for());
  // Sorted by kind name: the map's order on the wire is unspecified.
  const std::map<std::string, std::int64_t> failed(s.failed_analyses_by_kind().begin(),
                                                   s.failed_analyses_by_kind().end());
  w.Key("failed_analyses");
  w.BeginObject();
  for (const auto& [kind, count] : failed) w.Field(kind, static_cast<long long>(count));
  w.EndObject();
  w.Key("history");
  w.BeginArray();
  for (const auto& r : job.cycles()) {
    if (!r.accepted()) continue;
    w.BeginObject();
    w.Field("cycle", r.cycle());
    w.Field("attempts", r.attempt() + 1);
    w.Field("restoration", r.restoration());
    w.Field("objective", r.objective_trial());
    w.Field("max_violation", r.max_violation_trial());
    w.Field("max_approximation_error", r.max_approximation_error());
    w.Field("optimality_residual", r.optimality_residual());
    w.Field("lp_feasible", r.lp_feasible());
    w.Field("analyses", static_cast<long long>(r.analyses_total()));
    w.NumberArray("move_limits", ToVector(r.move_limits()));
    w.NumberArray("move_limits_next", ToVector(r.move_limits_next()));
    w.NumberArray("design", ToVector(r.x_trial_physical()));
    w.NumberArray("x_scaled", ToVector(r.x_trial_scaled()));
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
  return w.str() + "\n";
}

}  // namespace mbopt::client
