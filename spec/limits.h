// The bounds of the study and scene schema (docs/study.md, "Limits"): what a
// study may ask for before anything is allocated. They are checked once,
// where files and messages become spec types (spec/io) and where a study is
// laid out (MakeStudyLayout), so `mbopt validate`, `submit`, `run`, the
// server and `mbopt-worker eval` accept and refuse the same inputs.
#pragma once

#include <cstdint>

namespace mbopt::spec {

// Study and scene files: regular files no larger than this.
inline constexpr std::int64_t kMaxInputFileBytes = 16 << 20;

// Strings. A name is copied into every constraint row of its output (one
// per node and instant: a million rows at 10^5 instants), so a long name
// costs its length a million times; other strings (expressions, units,
// descriptions, references) are copied once.
inline constexpr int kMaxNameBytes = 256;
// An FMU archive a study carries (FmuModel::archive): a model, not a data set.
inline constexpr std::int64_t kMaxFmuArchiveBytes = std::int64_t{64} << 20;
inline constexpr int kMaxStringBytes = 64 << 10;

// Counts.
inline constexpr int kMaxTimeGridPoints = 1'000'000;
inline constexpr int kMaxLinkageFlexibleElements = 200;  // per linkage link
inline constexpr int kMaxDesignVariables = 10'000;
inline constexpr std::int64_t kMaxIntegratorSteps = 100'000'000;  // per analysis
inline constexpr int kMaxOptimizerCycles = 100'000;
inline constexpr int kMaxResponses = 10'000;
inline constexpr int kMaxLoadCases = 100;
// Designs of a sweep or sample: each is one analysis (per load case).
inline constexpr int kMaxDesignSetPoints = 100'000;
inline constexpr int kMaxXyPlots = 100;  // the study's `plots`: one figure each in the report

// Wall time of one analysis (integrator.max_wall_seconds): the default when
// a scene does not say, and the most it may say. Over it, the analysis ends
// as a `time_limit` failure.
inline constexpr double kDefaultAnalysisWallSeconds = 600.0;
inline constexpr double kMaxAnalysisWallSeconds = 7 * 86'400.0;

// The optimizer's memory for one study, estimated from its layout before
// any row exists (EstimateStudyMemoryBytes in spec/layout.h).
inline constexpr std::int64_t kMaxStudyMemoryBytes = std::int64_t{2} << 30;

}  // namespace mbopt::spec
