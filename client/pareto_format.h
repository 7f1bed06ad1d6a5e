// How the CLI shows a Pareto front's job (docs/study.md, "Pareto fronts"):
// one row per point with its level, both objectives, its run's end and
// whether it is on the front, dominated, infeasible, failed or not run, as
// a plain table, CSV or JSON (`mbopt results`, `mbopt run`); and one
// point's full results (`mbopt results JOB --point K`). Pure formatting; no
// I/O.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// The job computes a Pareto front (its study has a `pareto` section).
bool IsParetoJob(const v1::GetJobResponse& job);

// One point as the tables show it, the traded constraint's values in its
// unit. status: "front", "dominated", "infeasible", "failed" or "not run".
struct ParetoPointRow {
  int point = 0;  // 1-based
  const v1::CycleRecord* record = nullptr;
  double objective = 0;  // as reported (a maximized value as itself)
  double value = 0;      // the traded constraint's largest value, in its unit
  double level = 0;      // its level at this point, in its unit; NaN at the anchors
  // A front of three objectives: the second traded constraint's largest
  // value and level, in its unit (NaN on a front of two).
  double value3 = std::numeric_limits<double>::quiet_NaN();
  double level3 = std::numeric_limits<double>::quiet_NaN();
  std::string status;
};

// What a front trades its objective against, as the tables show it: the
// traded constraint (its name, its unit) or a second objective
// (SecondObjectiveLabel, in the objective's `unit`), and the factor from a
// record's pareto_value_si and pareto_level_si to the shown value: 1 / the
// unit's SI size for a constraint, -1 for a maximized objective (the runs
// minimize its negative, and a level is then a least value), else 1.
struct SecondObjectiveShown {
  std::string label;
  std::string unit;  // "" when none (or SI, for a constraint of an unknown unit)
  bool objective = false;
  bool maximized = false;
  double factor = 1.0;
};
SecondObjectiveShown ShowSecondObjective(const v1::Study& study);
// A front of three objectives' third: the second `against` constraint
// (label "" on a front of two).
SecondObjectiveShown ShowThirdObjective(const v1::Study& study);
bool IsFrontOfThree(const v1::Study& study);

// The watch's lines as each point's record arrives: "point" (1-based), F,
// the second objective and the level as the tables show them, the run's
// end and its cycles. Without the study (null), the raw values: SI for a
// constraint, as minimized for an objective.
std::string ParetoWatchHeader(const v1::Study* study);
std::string ParetoWatchRow(const v1::CycleRecord& record, const v1::Study* study);

// The traded constraint's name and unit ("" for SI), and the points in
// their order with dominance decided among the usable ones.
// A second objective that is an objective (`pareto { objective {...} }`)
// is named by SecondObjectiveLabel, in the objective's `unit` ("" when it
// has none), a maximized value shown as itself.
struct ParetoFront {
  std::string against;
  std::string unit;
  bool against_objective = false;
  bool against_maximized = false;  // its level is a least value, not a largest
  // A front of three objectives: the third's constraint and unit.
  bool three = false;
  std::string against3;
  std::string unit3;
  std::vector<ParetoPointRow> points;
};
ParetoFront FrontOfJob(const v1::GetJobResponse& job);

// "F2: max s1", "F2: sum of 2 terms", ...: a second objective's label.
std::string SecondObjectiveLabel(const v1::Objective& objective);

std::string ParetoTable(const v1::GetJobResponse& job);
std::string ParetoCsv(const v1::GetJobResponse& job);
std::string ParetoJson(const v1::GetJobResponse& job, const std::string& database = "");

// The point at the front's far end (1-based), whose run minimizes the
// second objective: its cycles' F is that, not the study's objective.
// A front of three objectives has two, points 2 and 3 (IsFarEnd).
int FarEndPoint(const v1::Study& study);
bool IsFarEnd(const v1::Study& study, int point);

// The cycle records of point `point`'s run (1-based), in their order:
// none for a point not run, and for a job logged before the runs' cycles
// were.
std::vector<const v1::CycleRecord*> PointRunCycles(const v1::GetJobResponse& job, int point);

// Point `point` (1-based) in full: its design, its values, each
// constraint's largest normalized value, its run and the run's cycle
// table (JSON: every point has its "history", one object per LP solve);
// as text or JSON.
// InvalidArgument naming the points there are when it has no such point.
absl::StatusOr<std::string> ParetoPointText(const v1::GetJobResponse& job, int point);
absl::StatusOr<std::string> ParetoPointJson(const v1::GetJobResponse& job, int point);

}  // namespace mbopt::client
