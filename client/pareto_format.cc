#include "client/pareto_format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/job_format.h"
#include "client/json_writer.h"
#include "client/record_cells.h"
#include "spec/pareto.h"
#include "spec/units.h"

namespace mbopt::client {
namespace {


std::string Heading(const std::string& name, const std::string& unit) {
  return unit.empty() ? name : absl::StrCat(name, " [", unit, "]");
}

const v1::CycleRecord* PointRecord(const v1::GetJobResponse& job, int point) {
  for (const v1::CycleRecord& r : job.cycles()) {
    if (r.pareto() && r.cycle() == point) return &r;
  }
  return nullptr;
}

absl::Status NoSuchPoint(const v1::GetJobResponse& job, int point) {
  const int done = static_cast<int>(FrontOfJob(job).points.size());
  return absl::InvalidArgumentError(absl::StrCat(
      "--point ", point, ": job ", job.summary().job_id(), " has ",
      done == 0 ? std::string("no point yet") : absl::StrCat("points 1 to ", done), " (of ",
      job.summary().max_cycles(), ")"));
}

}  // namespace

bool IsParetoJob(const v1::GetJobResponse& job) {
  if (job.summary().pareto()) return true;
  if (job.has_study() && job.study().has_pareto()) return true;
  return job.cycles_size() > 0 && job.cycles(0).pareto();
}

std::string ParetoWatchHeader() {
  return absl::StrFormat("%5s %14s %14s %14s %-10s %6s", "point", "F", "value (SI)", "level (SI)", "run", "cycles");
}

std::string ParetoWatchRow(const v1::CycleRecord& r) {
  return absl::StrFormat("%5d %14s %14s %14s %-10s %6d", r.cycle(), CellValue(r.objective_trial(), "-"),
                         CellValue(r.pareto_value_si(), "-"), CellValue(r.pareto_level_si(), "-"), r.pareto_state(),
                         r.pareto_cycles());
}

std::string SecondObjectiveLabel(const v1::Objective& o) {
  switch (o.form_case()) {
    case v1::Objective::kMinimize: return absl::StrCat("F2: ", o.minimize());
    case v1::Objective::kMaximize: return absl::StrCat("F2: ", o.maximize(), " (maximized)");
    case v1::Objective::kMinimizeMaxOf:
      return absl::StrCat("F2: max ", o.reduction() == v1::REDUCTION_MAX_ABS ? "|" : "", o.minimize_max_of(),
                          o.reduction() == v1::REDUCTION_MAX_ABS ? "|" : "");
    case v1::Objective::kMinimizeMaxOver:
      return absl::StrCat("F2: largest of ", o.minimize_max_over().terms_size(), " terms");
    case v1::Objective::kMinimizeSum: return absl::StrCat("F2: sum of ", o.minimize_sum().terms_size(), " terms");
    default: return "F2";
  }
}

ParetoFront FrontOfJob(const v1::GetJobResponse& job) {
  ParetoFront front;
  const v1::Pareto& pareto = job.study().pareto();
  // The second objective as the runs minimized it (a maximized value's
  // negative) is what the records hold; it is shown as the study writes it.
  double second_sign = 1.0;
  if (pareto.has_objective()) {
    front.against_objective = true;
    front.against = SecondObjectiveLabel(pareto.objective());
    front.unit = pareto.objective().unit();
    if (pareto.objective().form_case() == v1::Objective::kMaximize) {
      second_sign = -1.0;
      front.against_maximized = true;
    }
  } else {
    front.against = pareto.against();
    for (const auto& c : job.study().constraints()) {
      if (c.name() == front.against) front.unit = c.unit();
    }
  }
  double si_per_unit = 1.0;
  // An objective's values are in its unit already.
  if (!front.unit.empty() && !front.against_objective) {
    if (absl::StatusOr<spec::Unit> unit = spec::FindUnit(front.unit); unit.ok()) {
      si_per_unit = unit->si_per_unit;
    } else {
      front.unit.clear();  // shown in SI rather than mislabelled
    }
  }
  // The first objective as the optimizer minimized it.
  const double sign = job.study().objective().maximize().empty() ? 1.0 : -1.0;
  std::vector<spec::FrontPoint> usable;
  for (const v1::CycleRecord& r : job.cycles()) {
    if (!r.pareto()) continue;
    ParetoPointRow row;
    row.point = r.cycle();
    row.record = &r;
    row.objective = r.objective_trial();
    row.value = second_sign * r.pareto_value_si() / si_per_unit;
    row.level = second_sign * r.pareto_level_si() / si_per_unit;
    if (r.pareto_state() == "not_run") {
      row.status = "not run";
    } else if (!r.accepted()) {
      row.status = r.pareto_state() == "failed" || !std::isfinite(r.objective_trial()) ? "failed" : "infeasible";
    }
    usable.push_back({sign * row.objective, second_sign * row.value, row.status.empty()});
    front.points.push_back(std::move(row));
  }
  const std::vector<bool> dominated = spec::DominatedPoints(usable);
  for (size_t k = 0; k < front.points.size(); ++k) {
    if (front.points[k].status.empty()) front.points[k].status = dominated[k] ? "dominated" : "front";
  }
  return front;
}

std::string ParetoTable(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  const ParetoFront front = FrontOfJob(job);
  std::string out = SummaryText(s, job.has_study() ? &job.study() : nullptr);
  out += '\n';
  std::vector<std::string> header = {"point", Heading("level", front.unit),
                                     Heading("F", s.objective_unit()), Heading(front.against, front.unit),
                                     "maxg", "run", "cycles"};
  for (int i = 0; i < s.design_names_size(); ++i) {
    header.push_back(Heading(s.design_names(i), i < s.design_units_size() ? s.design_units(i) : ""));
  }
  header.push_back("status");
  std::vector<std::vector<std::string>> rows = {header};
  for (const ParetoPointRow& p : front.points) {
    const v1::CycleRecord& r = *p.record;
    std::vector<std::string> row = {std::to_string(p.point), CellValue(p.level, "-"), CellValue(p.objective, "-"),
                                    CellValue(p.value, "-"), CellValue(r.max_violation_trial(), "-"), r.pareto_state(),
                                    std::to_string(r.pareto_cycles())};
    for (int i = 0; i < s.design_names_size(); ++i) {
      row.push_back(p.status == "not run" ? "-" : CellValue(TrialPhysical(r, i), "-"));
    }
    row.push_back(p.status);
    rows.push_back(std::move(row));
  }
  out += AlignedRows(rows);
  out += absl::StrCat("level: the limit on ", front.against,
                      " for the point (none at the two ends); maxg: the point's run's largest (g - limit) / scale\n");
  for (const ParetoPointRow& p : front.points) {
    if (!p.record->rejection_reason().empty()) {
      out += absl::StrCat("point ", p.point, ": ", p.record->rejection_reason(), "\n");
    }
  }
  return out;
}

std::string ParetoCsv(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  const ParetoFront front = FrontOfJob(job);
  auto cell = [](double v) { return std::isfinite(v) ? JsonWriter::FormatDouble(v) : std::string(); };
  // A label with spaces is no column name: an objective's column is "second_objective".
  std::string out = absl::StrCat("point,level,objective,", front.against_objective ? "second_objective" : front.against,
                                 ",max_violation,run_state,cycles,analyses");
  for (const auto& name : s.design_names()) out += "," + name;
  out += ",status,reason\n";
  for (const ParetoPointRow& p : front.points) {
    const v1::CycleRecord& r = *p.record;
    out += absl::StrCat(p.point, ",", cell(p.level), ",", cell(p.objective), ",", cell(p.value), ",",
                        cell(r.max_violation_trial()), ",", r.pareto_state(), ",", r.pareto_cycles(), ",",
                        r.pareto_analyses());
    for (int i = 0; i < s.design_names_size(); ++i) out += "," + cell(TrialPhysical(r, i));
    std::string reason;
    for (char ch : r.rejection_reason()) reason += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    out += "," + p.status + "," + (reason.empty() ? "" : "\"" + reason + "\"") + "\n";
  }
  return out;
}

namespace {

void PointObject(const v1::GetJobResponse& job, const ParetoPointRow& p, JsonWriter& w) {
  const v1::JobSummary& s = job.summary();
  const v1::CycleRecord& r = *p.record;
  w.BeginObject();
  w.Field("point", p.point);
  w.Field("level", p.level);
  w.Field("objective", p.objective);
  w.Field("value", p.value);
  w.Field("max_violation", r.max_violation_trial());
  w.Field("run_state", r.pareto_state());
  w.Field("cycles", r.pareto_cycles());
  w.Field("analyses", static_cast<long long>(r.pareto_analyses()));
  w.Key("design");
  w.BeginObject();
  for (int i = 0; i < s.design_names_size(); ++i) w.Field(s.design_names(i), TrialPhysical(r, i));
  w.EndObject();
  w.NumberArray("x_scaled", std::vector<double>(r.x_trial_scaled().begin(), r.x_trial_scaled().end()));
  w.Key("constraints");
  w.BeginObject();
  for (int c = 0; c < job.study().constraints_size(); ++c) w.Field(job.study().constraints(c).name(), ConstraintViolation(r, c));
  w.EndObject();
  w.Field("status", p.status);
  w.Field("reason", r.rejection_reason());
  w.EndObject();
}

}  // namespace

std::string ParetoJson(const v1::GetJobResponse& job, const std::string& database) {
  const v1::JobSummary& s = job.summary();
  const ParetoFront front = FrontOfJob(job);
  JsonWriter w;
  w.BeginObject();
  w.Field("job_id", s.job_id());
  if (!database.empty()) w.Field("database", database);
  w.Field("study", s.study_name());
  w.Field("status", StateName(s.state()));
  w.Field("form", "pareto");
  w.Field("against", front.against);
  w.Field("against_unit", front.unit);
  w.Field("objective_unit", s.objective_unit());
  w.Field("points_total", s.max_cycles());
  w.Field("points_done", s.cycles());
  w.Field("analyses", static_cast<long long>(s.analyses()));
  w.Field("message", s.message());
  w.Key("points");
  w.BeginArray();
  for (const ParetoPointRow& p : front.points) PointObject(job, p, w);
  w.EndArray();
  w.EndObject();
  return w.str() + "\n";
}

absl::StatusOr<std::string> ParetoPointText(const v1::GetJobResponse& job, int point) {
  const ParetoFront front = FrontOfJob(job);
  const ParetoPointRow* p = nullptr;
  for (const ParetoPointRow& row : front.points) {
    if (row.point == point) p = &row;
  }
  if (p == nullptr || PointRecord(job, point) == nullptr) return NoSuchPoint(job, point);
  const v1::JobSummary& s = job.summary();
  const v1::CycleRecord& r = *p->record;
  std::string out = absl::StrFormat("job %s, %s: point %d of %d (%s)\n", s.job_id(), s.study_name(), point,
                                    s.max_cycles(), p->status);
  const std::string unit = front.unit.empty() ? "" : " " + front.unit;
  out += std::isfinite(p->level) ? absl::StrFormat("level:       %s %s %.9g%s\n", front.against,
                                                    front.against_maximized ? ">=" : "<=", p->level, unit)
                                  : absl::StrFormat("level:       none (an end of the front)\n");
  out += absl::StrFormat("objective:   %s%s\n", CellValue(p->objective, "-"),
                         s.objective_unit().empty() ? "" : " " + s.objective_unit());
  out += absl::StrFormat("%-12s %s%s\n", front.against + ":", CellValue(p->value, "-"), unit);
  out += absl::StrFormat("maxg:        %s\n", CellValue(r.max_violation_trial(), "-"));
  out += absl::StrFormat("run:         %s after %d cycles, %d analyses\n", r.pareto_state(), r.pareto_cycles(),
                         static_cast<long long>(r.pareto_analyses()));
  if (!r.rejection_reason().empty()) out += "reason:      " + r.rejection_reason() + "\n";
  out += "design:\n";
  for (int i = 0; i < s.design_names_size(); ++i) {
    const std::string design_unit = i < s.design_units_size() ? s.design_units(i) : "";
    out += absl::StrFormat("  %-12s %.9g%s\n", s.design_names(i), TrialPhysical(r, i),
                           design_unit.empty() ? "" : " " + design_unit);
  }
  out += "constraints (largest (g - limit) / scale against the study's limits, > 0 violated):\n";
  for (int c = 0; c < job.study().constraints_size(); ++c) {
    out += absl::StrFormat("  %-12s %s\n", job.study().constraints(c).name(), CellValue(ConstraintViolation(r, c), "-"));
  }
  return out;
}

absl::StatusOr<std::string> ParetoPointJson(const v1::GetJobResponse& job, int point) {
  const ParetoFront front = FrontOfJob(job);
  for (const ParetoPointRow& p : front.points) {
    if (p.point != point) continue;
    JsonWriter w;
    PointObject(job, p, w);
    return w.str() + "\n";
  }
  return NoSuchPoint(job, point);
}

}  // namespace mbopt::client
