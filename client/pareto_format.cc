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
  return job.cycles_size() > 0 && (job.cycles(0).pareto() || job.cycles(0).pareto_point() > 0);
}

bool IsFrontOfThree(const v1::Study& study) { return study.pareto().against_size() == 2; }

int FarEndPoint(const v1::Study& study) {
  if (IsFrontOfThree(study)) return 2;
  return study.pareto().points() > 0 ? study.pareto().points() : spec::kDefaultParetoPoints;
}

bool IsFarEnd(const v1::Study& study, int point) {
  return point == FarEndPoint(study) || (IsFrontOfThree(study) && point == 3);
}

std::vector<const v1::CycleRecord*> PointRunCycles(const v1::GetJobResponse& job, int point) {
  std::vector<const v1::CycleRecord*> cycles;
  for (const v1::CycleRecord& r : job.cycles()) {
    if (r.pareto_point() == point) cycles.push_back(&r);
  }
  return cycles;
}

namespace {

// The watch's headings of the second objective and its level; a label
// wider than the column widens both columns (the values are aligned to
// their right edge).
struct WatchColumns {
  std::string second = "value (raw)";
  std::string level = "level (raw)";
  double factor = 1.0;
  int width = 14;
  // A front of three objectives: the third's columns.
  bool three = false;
  std::string third = "value3 (raw)";
  std::string level3 = "level3 (raw)";
  double factor3 = 1.0;
};

WatchColumns WatchColumnsOf(const v1::Study* study) {
  WatchColumns c;
  if (study != nullptr) {
    const SecondObjectiveShown shown = ShowSecondObjective(*study);
    c.second = Heading(shown.label, shown.unit);
    c.level = Heading("level", shown.unit);
    c.factor = shown.factor;
    c.three = IsFrontOfThree(*study);
    if (c.three) {
      const SecondObjectiveShown third = ShowThirdObjective(*study);
      c.third = Heading(third.label, third.unit);
      c.level3 = Heading("level", third.unit);
      c.factor3 = third.factor;
    }
  }
  c.width = std::max<int>({c.width, static_cast<int>(c.second.size()), static_cast<int>(c.level.size())});
  if (c.three) c.width = std::max<int>({c.width, static_cast<int>(c.third.size()), static_cast<int>(c.level3.size())});
  return c;
}

}  // namespace

std::string ParetoWatchHeader(const v1::Study* study) {
  const WatchColumns c = WatchColumnsOf(study);
  const std::string third =
      c.three ? absl::StrFormat(" %*s %*s", c.width, c.third, c.width, c.level3) : std::string();
  return absl::StrFormat("%5s %14s %*s %*s%s %-10s %6s", "point", "F", c.width, c.second, c.width, c.level, third,
                         "run", "cycles");
}

std::string ParetoWatchRow(const v1::CycleRecord& r, const v1::Study* study) {
  const WatchColumns c = WatchColumnsOf(study);
  // Without the study, a record of a front of three still shows its third.
  const bool three = c.three || (study == nullptr && r.pareto_three());
  const std::string third = three ? absl::StrFormat(" %*s %*s", c.width, CellValue(c.factor3 * r.pareto_value3_si(), "-"),
                                                    c.width, CellValue(c.factor3 * r.pareto_level3_si(), "-"))
                                  : std::string();
  return absl::StrFormat("%5d %14s %*s %*s%s %-10s %6d", r.cycle(), CellValue(r.objective_trial(), "-"), c.width,
                         CellValue(c.factor * r.pareto_value_si(), "-"), c.width,
                         CellValue(c.factor * r.pareto_level_si(), "-"), third, r.pareto_state(), r.pareto_cycles());
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

namespace {

std::string SharedTermUnit(const v1::Objective& o) {
  const auto& terms = o.minimize_max_over().terms();
  if (terms.empty()) return "";
  for (const v1::WeightedTerm& t : terms) {
    const bool unweighted = t.weight() == 0.0 || t.weight() == 1.0;  // 0: not given
    if (t.unit().empty() || t.unit() != terms[0].unit() || !unweighted) return "";
  }
  return terms[0].unit();
}

// A traded constraint named `name`, in its unit.
SecondObjectiveShown ShowConstraint(const v1::Study& study, const std::string& name) {
  SecondObjectiveShown shown;
  shown.label = name;
  for (const auto& c : study.constraints()) {
    if (c.name() == shown.label) shown.unit = c.unit();
  }
  if (!shown.unit.empty()) {
    if (absl::StatusOr<spec::Unit> unit = spec::FindUnit(shown.unit); unit.ok()) {
      shown.factor = 1.0 / unit->si_per_unit;
    } else {
      shown.unit.clear();  // shown in SI rather than mislabelled
    }
  }
  return shown;
}

}  // namespace

SecondObjectiveShown ShowSecondObjective(const v1::Study& study) {
  SecondObjectiveShown shown;
  const v1::Pareto& pareto = study.pareto();
  if (pareto.has_objective()) {
    shown.objective = true;
    shown.label = SecondObjectiveLabel(pareto.objective());
    // An objective's values are in its unit already. A largest of terms
    // has no unit of its own (the loader refuses one); its terms' values are
    // each in their term's unit, so one unit shared by every term, none of
    // them weighted, is the largest's unit too.
    shown.unit = pareto.objective().unit();
    if (pareto.objective().form_case() == v1::Objective::kMinimizeMaxOver) shown.unit = SharedTermUnit(pareto.objective());
    // The runs minimize a maximized value's negative; it is shown as itself.
    if (pareto.objective().form_case() == v1::Objective::kMaximize) {
      shown.maximized = true;
      shown.factor = -1.0;
    }
    return shown;
  }
  return ShowConstraint(study, pareto.against_size() > 0 ? pareto.against(0) : "");
}

SecondObjectiveShown ShowThirdObjective(const v1::Study& study) {
  return ShowConstraint(study, IsFrontOfThree(study) ? study.pareto().against(1) : "");
}

ParetoFront FrontOfJob(const v1::GetJobResponse& job) {
  ParetoFront front;
  const SecondObjectiveShown shown = ShowSecondObjective(job.study());
  front.against = shown.label;
  front.unit = shown.unit;
  front.against_objective = shown.objective;
  front.against_maximized = shown.maximized;
  const SecondObjectiveShown third = ShowThirdObjective(job.study());
  front.three = IsFrontOfThree(job.study());
  front.against3 = third.label;
  front.unit3 = third.unit;
  // Dominance is decided on the second objective as the runs minimized it.
  const double second_sign = shown.maximized ? -1.0 : 1.0;
  // The first objective as the optimizer minimized it.
  const double sign = job.study().objective().maximize().empty() ? 1.0 : -1.0;
  std::vector<spec::FrontPoint> usable;
  for (const v1::CycleRecord& r : job.cycles()) {
    if (!r.pareto()) continue;
    ParetoPointRow row;
    row.point = r.cycle();
    row.record = &r;
    row.objective = r.objective_trial();
    row.value = shown.factor * r.pareto_value_si();
    row.level = shown.factor * r.pareto_level_si();
    if (front.three) {
      row.value3 = third.factor * r.pareto_value3_si();
      row.level3 = third.factor * r.pareto_level3_si();
    }
    if (r.pareto_state() == "not_run") {
      row.status = "not run";
    } else if (!r.accepted()) {
      row.status = r.pareto_state() == "failed" || !std::isfinite(r.objective_trial()) ? "failed" : "infeasible";
    }
    usable.push_back({sign * row.objective, second_sign * row.value, row.status.empty(),
                      front.three ? row.value3 : 0.0});
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
  std::vector<std::string> header = {"point", Heading("level", front.unit)};
  if (front.three) header.push_back(Heading("level3", front.unit3));
  header.insert(header.end(), {Heading("F", s.objective_unit()), Heading(front.against, front.unit)});
  if (front.three) header.push_back(Heading(front.against3, front.unit3));
  header.insert(header.end(), {"maxg", "run", "cycles"});
  for (int i = 0; i < s.design_names_size(); ++i) {
    header.push_back(Heading(s.design_names(i), i < s.design_units_size() ? s.design_units(i) : ""));
  }
  header.push_back("status");
  std::vector<std::vector<std::string>> rows = {header};
  for (const ParetoPointRow& p : front.points) {
    const v1::CycleRecord& r = *p.record;
    std::vector<std::string> row = {std::to_string(p.point), CellValue(p.level, "-")};
    if (front.three) row.push_back(CellValue(p.level3, "-"));
    row.insert(row.end(), {CellValue(p.objective, "-"), CellValue(p.value, "-")});
    if (front.three) row.push_back(CellValue(p.value3, "-"));
    row.insert(row.end(), {CellValue(r.max_violation_trial(), "-"), r.pareto_state(), std::to_string(r.pareto_cycles())});
    for (int i = 0; i < s.design_names_size(); ++i) {
      row.push_back(p.status == "not run" ? "-" : CellValue(TrialPhysical(r, i), "-"));
    }
    row.push_back(p.status);
    rows.push_back(std::move(row));
  }
  out += AlignedRows(rows);
  if (front.three) {
    out += absl::StrCat("level, level3: the limits on ", front.against, " and ", front.against3,
                        " for the point (none at the three anchors, points 1 to 3: each objective's own least "
                        "value); maxg: the point's run's largest (g - limit) / scale\n");
  } else {
    out += absl::StrCat("level: the limit on ", front.against,
                        " for the point (none at the two ends); maxg: the point's run's largest (g - limit) / scale\n");
  }
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
  std::string out = absl::StrCat("point,level,", front.three ? "level3," : "", "objective,",
                                 front.against_objective ? "second_objective" : front.against,
                                 front.three ? "," + front.against3 : "", ",max_violation,run_state,cycles,analyses");
  for (const auto& name : s.design_names()) out += "," + name;
  out += ",status,reason\n";
  for (const ParetoPointRow& p : front.points) {
    const v1::CycleRecord& r = *p.record;
    out += absl::StrCat(p.point, ",", cell(p.level), ",", front.three ? cell(p.level3) + "," : "",
                        cell(p.objective), ",", cell(p.value), ",", front.three ? cell(p.value3) + "," : "",
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
  if (r.pareto_three()) {
    w.Field("level3", p.level3);
    w.Field("value3", p.value3);
  }
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
  // Every LP solve of the point's run, rejected trials included.
  w.Key("history");
  w.BeginArray();
  for (const v1::CycleRecord* c : PointRunCycles(job, p.point)) {
    w.BeginObject();
    w.Field("cycle", c->cycle());
    w.Field("attempt", c->attempt());
    w.Field("accepted", c->accepted());
    w.Field("restoration", c->restoration());
    w.Field("objective", c->objective_trial());
    w.Field("max_violation", c->max_violation_trial());
    w.Field("max_approximation_error", c->max_approximation_error());
    w.Field("optimality_residual", c->optimality_residual());
    w.Field("lp_feasible", c->lp_feasible());
    w.Field("analyses", static_cast<long long>(c->analyses_total()));
    w.NumberArray("design", std::vector<double>(c->x_trial_physical().begin(), c->x_trial_physical().end()));
    w.EndObject();
  }
  w.EndArray();
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
  if (front.three) {
    w.Field("against3", front.against3);
    w.Field("against3_unit", front.unit3);
  }
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
                                  : absl::StrFormat("level:       none (%s)\n",
                                                    front.three ? "an anchor" : "an end of the front");
  out += absl::StrFormat("objective:   %s%s\n", CellValue(p->objective, "-"),
                         s.objective_unit().empty() ? "" : " " + s.objective_unit());
  out += absl::StrFormat("%-12s %s%s\n", front.against + ":", CellValue(p->value, "-"), unit);
  if (front.three) {
    const std::string unit3 = front.unit3.empty() ? "" : " " + front.unit3;
    out += std::isfinite(p->level3)
               ? absl::StrFormat("level3:      %s <= %.9g%s\n", front.against3, p->level3, unit3)
               : absl::StrFormat("level3:      none (an anchor)\n");
    out += absl::StrFormat("%-12s %s%s\n", front.against3 + ":", CellValue(p->value3, "-"), unit3);
  }
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
  const std::vector<const v1::CycleRecord*> cycles = PointRunCycles(job, point);
  if (!cycles.empty()) {
    // The far end's run minimizes the second objective, not the study's;
    // the server reports its F as that objective is shown, in its unit.
    const bool far_end = IsFarEnd(job.study(), point);
    const bool third = IsFrontOfThree(job.study()) && point == 3;
    const std::string& far_unit = third ? front.unit3 : front.unit;
    out += absl::StrCat("cycles of its run (F: ",
                        far_end ? absl::StrCat(third ? "the third objective " : "the second objective ",
                                               third ? front.against3 : front.against,
                                               far_unit.empty() ? "" : " [" + far_unit + "]", ", which the run optimizes")
                                : "the study's objective",
                        "; maxg: against the run's own limits, its level included):\n");
    out += CycleTableHeader();
    out += '\n';
    for (const v1::CycleRecord* c : cycles) {
      out += CycleTableRow(*c);
      out += '\n';
    }
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
