#include "client/design_set_format.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "client/job_format.h"
#include "client/json_writer.h"
#include "client/record_cells.h"

namespace mbopt::client {
namespace {

std::string Status(const v1::CycleRecord& r) { return r.failure_kind().empty() ? "ok" : r.failure_kind(); }

std::vector<std::string> ConstraintNames(const v1::GetJobResponse& job) {
  std::vector<std::string> names;
  for (const auto& c : job.study().constraints()) names.push_back(c.name());
  return names;
}

// The header cell of variable i: "name [unit]".
std::string VariableHeading(const v1::JobSummary& s, int i) {
  const std::string unit = i < s.design_units_size() ? s.design_units(i) : "";
  return s.design_names(i) + (unit.empty() ? "" : " [" + unit + "]");
}

}  // namespace

bool IsDesignSetJob(const v1::GetJobResponse& job) {
  if (job.summary().design_set()) return true;
  if (job.has_study() && (job.study().has_sweep() || job.study().has_sample())) return true;
  return job.cycles_size() > 0 && job.cycles(0).design_set();
}

std::string DesignWatchHeader() {
  return absl::StrFormat("%6s %14s %10s %-12s  %s", "design", "F", "maxg", "status", "design variables");
}

std::string DesignWatchRow(const v1::CycleRecord& r) {
  std::string variables;
  for (int i = 0; i < r.x_trial_physical_size(); ++i) {
    variables += (i == 0 ? "" : " ") + absl::StrFormat("%.7g", r.x_trial_physical(i));
  }
  return absl::StrFormat("%6d %14s %10s %-12s  %s", r.cycle(), CellValue(r.objective_trial(), "-"),
                         CellValue(r.max_violation_trial(), "-"), Status(r), variables);
}

std::string DesignSetTable(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  std::string out = SummaryText(s, job.has_study() ? &job.study() : nullptr);
  out += '\n';
  const std::vector<std::string> constraints = ConstraintNames(job);
  std::vector<std::string> header = {"design"};
  for (int i = 0; i < s.design_names_size(); ++i) header.push_back(VariableHeading(s, i));
  header.push_back("F" + (s.objective_unit().empty() ? std::string() : " [" + s.objective_unit() + "]"));
  header.push_back("maxg");
  for (const std::string& c : constraints) header.push_back(c);
  header.push_back("status");
  std::vector<std::vector<std::string>> rows = {header};
  for (const v1::CycleRecord& r : job.cycles()) {
    std::vector<std::string> row = {std::to_string(r.cycle())};
    for (int i = 0; i < s.design_names_size(); ++i) row.push_back(CellValue(TrialPhysical(r, i), "-"));
    row.push_back(CellValue(r.objective_trial(), "-"));
    row.push_back(CellValue(r.max_violation_trial(), "-"));
    for (size_t c = 0; c < constraints.size(); ++c) row.push_back(CellValue(ConstraintViolation(r, static_cast<int>(c)), "-"));
    row.push_back(Status(r));
    rows.push_back(std::move(row));
  }
  out += AlignedRows(rows);
  out += "maxg and the constraint columns: the largest (g - limit) / scale, > 0 violated\n";
  return out;
}

std::string DesignSetCsv(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  const std::vector<std::string> constraints = ConstraintNames(job);
  std::string out = "design";
  for (const auto& name : s.design_names()) out += "," + name;
  out += ",objective,max_violation";
  for (const std::string& c : constraints) out += "," + c;
  out += ",status,failure_reason\n";
  // An empty cell is a value the analysis did not give.
  auto cell = [](double v) { return std::isfinite(v) ? JsonWriter::FormatDouble(v) : std::string(); };
  for (const v1::CycleRecord& r : job.cycles()) {
    out += std::to_string(r.cycle());
    for (int i = 0; i < s.design_names_size(); ++i) out += "," + cell(TrialPhysical(r, i));
    out += "," + cell(r.objective_trial()) + "," + cell(r.max_violation_trial());
    for (size_t c = 0; c < constraints.size(); ++c) out += "," + cell(ConstraintViolation(r, static_cast<int>(c)));
    // A reason is free text: quoted, its quotes doubled (RFC 4180).
    std::string reason;
    for (char ch : r.rejection_reason()) reason += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    out += "," + Status(r) + "," + (reason.empty() ? "" : "\"" + reason + "\"") + "\n";
  }
  return out;
}

std::string DesignSetJson(const v1::GetJobResponse& job, const std::string& database) {
  const v1::JobSummary& s = job.summary();
  const std::vector<std::string> constraints = ConstraintNames(job);
  JsonWriter w;
  w.BeginObject();
  w.Field("job_id", s.job_id());
  if (!database.empty()) w.Field("database", database);
  w.Field("study", s.study_name());
  w.Field("status", StateName(s.state()));
  w.Field("form", job.study().has_sample() ? "sample" : "sweep");
  w.Field("designs_total", s.max_cycles());
  w.Field("designs_done", s.cycles());
  w.Field("analyses", static_cast<long long>(s.analyses()));
  w.Field("objective_unit", s.objective_unit());
  w.Field("best_objective", s.objective());
  w.Field("best_max_violation", s.max_violation());
  w.Key("variables");
  w.BeginArray();
  for (int i = 0; i < s.design_names_size(); ++i) {
    w.BeginObject();
    w.Field("name", s.design_names(i));
    for (const auto& v : job.study().variables()) {
      if (v.name() != s.design_names(i)) continue;
      w.Field("parameter", v.parameter());
      w.Field("scale", v.scale() == 0 ? 1.0 : v.scale());
    }
    w.Field("unit", i < s.design_units_size() ? s.design_units(i) : "");
    w.EndObject();
  }
  w.EndArray();
  w.Key("constraints");
  w.BeginArray();
  for (const std::string& c : constraints) w.String(c);
  w.EndArray();
  w.Field("message", s.message());
  const std::map<std::string, std::int64_t> failed(s.failed_analyses_by_kind().begin(),
                                                   s.failed_analyses_by_kind().end());
  w.Key("failed_analyses");
  w.BeginObject();
  for (const auto& [kind, count] : failed) w.Field(kind, static_cast<long long>(count));
  w.EndObject();
  w.Key("designs");
  w.BeginArray();
  for (const v1::CycleRecord& r : job.cycles()) {
    w.BeginObject();
    w.Field("design", r.cycle());
    w.Key("values");
    w.BeginObject();
    for (int i = 0; i < s.design_names_size(); ++i) w.Field(s.design_names(i), TrialPhysical(r, i));
    w.EndObject();
    w.NumberArray("x_scaled", std::vector<double>(r.x_trial_scaled().begin(), r.x_trial_scaled().end()));
    w.Field("objective", r.objective_trial());
    w.Field("max_violation", r.max_violation_trial());
    w.Key("constraints");
    w.BeginObject();
    for (size_t c = 0; c < constraints.size(); ++c) w.Field(constraints[c], ConstraintViolation(r, static_cast<int>(c)));
    w.EndObject();
    w.Field("status", Status(r));
    w.Field("failure_reason", r.rejection_reason());
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
  return w.str() + "\n";
}

}  // namespace mbopt::client
