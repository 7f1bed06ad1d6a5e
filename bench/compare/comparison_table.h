// The comparison table of one study: the best known objective (the lowest
// objective any method analysed at a design feasible within the violation
// tolerance), and per method the analyses it needed to reach it, its final
// values, total analyses and wall time; as Markdown.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bench/compare/method_run.h"

namespace mbopt::compare {

struct TargetRule {
  double objective_fraction = 0.005;  // within 0.5 % of the best known F
  double violation = 0.002;           // feasible within 0.2 %
  // Where the best F is (near) zero the 0.5 % has nothing to bite on: the
  // tolerance is objective_fraction * max(|F_best|, floor * |F(x0)|).
  double floor_fraction_of_initial = 0.01;
};

struct StudyComparison {
  std::string study;
  std::string reference_note;  // published values, for the reader
  double initial_objective = 0;
  double best_objective = 0;   // NaN if no method found a feasible design
  double target_objective = 0;
  std::vector<MethodRun> runs;
};

StudyComparison Compare(std::string study, std::string reference_note, std::vector<MethodRun> runs,
                        const TargetRule& rule);

// Analyses at the first candidate meeting the target; nullopt if none did.
std::optional<std::int64_t> AnalysesToTarget(const MethodRun& run, const StudyComparison& c,
                                             const TargetRule& rule);

std::string ComparisonMarkdown(const StudyComparison& c, const TargetRule& rule);

// Plain sentences on who reached the target first and who ended lowest,
// derived from the runs.
std::string Verdict(const StudyComparison& c, const TargetRule& rule);

}  // namespace mbopt::compare
