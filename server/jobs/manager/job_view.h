// What the job manager tells of a job: its summary (List, and every
// view), and a view of its records from an index on (Get, Watch).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "server/jobs/job_state.h"
#include "server/jobs/job.h"  // slp::CycleRecord
#include "spec/layout.h"

namespace mbopt::jobs::manager {

struct JobSummaryData {
  std::string job_id;
  std::string study_name;
  std::string owner;  // who submitted it; "" on a server without tokens
  jobs::JobState state = jobs::JobState::kQueued;
  int cycles = 0;
  std::int64_t analyses = 0;
  // The result's F, in objective_unit (a maximized value as itself), and
  // maxg (normalized, > 0 violated);
  // NaN while no design has been analysed (and for a job that failed there).
  double objective = std::numeric_limits<double>::quiet_NaN();
  std::string objective_unit;
  double max_violation = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> design_names;
  std::vector<double> design;     // physical: scale * x, parameter units
  std::vector<std::string> design_units;
  double wall_seconds = 0;
  std::string message;
  std::int64_t created_unix_ms = 0;
  int max_cycles = 0;
  // Failed analyses so far by failure kind name (spec::FailureKindName).
  std::map<std::string, std::int64_t> failed_analyses_by_kind;
  // A running job whose analyses no registered worker can run: why
  // (e.g. the driver its scene names); "" otherwise.
  std::string waiting_for;
  // A design set (sweep or sample): cycles are its designs done and
  // max_cycles all of them.
  bool design_set = false;
  // A Pareto front (design_set is set too): cycles are its points done.
  bool pareto = false;
};

// What a client needs to show a job's records with names and units.
struct JobView {
  JobSummaryData summary;
  std::vector<slp::CycleRecord> records;  // from the requested index on
  std::size_t first_record = 0;           // index of records[0] in the job's log
  std::int64_t version = 0;               // changes with every record or state change
  bool ended = false;                     // the job is not running (nothing more will come)
  // The study's layout (constraint rows' names, for worst_* indices);
  // null when the study is not usable.
  std::shared_ptr<const spec::StudyLayout> layout;
  std::vector<double> variable_scales;    // physical = scale * x
  double objective_sign = 1.0;            // reported F = sign * the records' F (-1: maximized)
  // A Pareto front's far end, the point whose run minimizes the second
  // objective (0: not a front): its run's F is no reported objective but
  // the second objective divided by its rows' scale, reported in the second
  // objective's unit (times pareto_far_end_factor: the rows' scale times
  // pareto_shown_factor).
  int pareto_far_end = 0;
  double pareto_far_end_factor = 1.0;
  double pareto_third_end_factor = 1.0;  // point 3 of a front of three objectives, the third's
  // A front of three objectives: its points 2 and 3 minimize the second
  // and third objectives (pareto_far_end is 2).
  bool pareto_three = false;
  // A front's point record's second objective and level as shown
  // (CycleRecord.pareto_value): factor * the record's. 1 / the unit's SI
  // size for a traded constraint; -1 for a maximized second objective (the
  // runs minimize its negative), else 1.
  double pareto_shown_factor = 1.0;
  double pareto_third_shown_factor = 1.0;  // the third objective's, as pareto_shown_factor
  std::string study_bytes;

  // What record r's F is multiplied by as reported: the objective's sign,
  // or at a front's far end the factor to the objective its run minimizes,
  // in that objective's unit.
  double ReportedFactor(const slp::CycleRecord& r) const {
    if (pareto_far_end > 0 && r.pareto_point == pareto_far_end) return pareto_far_end_factor;
    if (pareto_three && pareto_far_end > 0 && r.pareto_point == pareto_far_end + 1) return pareto_third_end_factor;
    return objective_sign;
  }
};

// Who a view is for: a reader (Get) gets the study's bytes as well; a
// watcher does not need them.
enum class JobViewFor { kReader, kWatcher };

}  // namespace mbopt::jobs::manager
