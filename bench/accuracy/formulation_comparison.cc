#include "bench/accuracy/formulation_comparison.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <variant>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/io/study_io.h"
#include "worker/engine/analysis.h"

namespace mbopt::accuracy {
namespace {

struct Design {
  const char* name;
  std::vector<double> areas_m2;
};

struct Measured {
  std::vector<double> peak_ratio;  // per stress output: max |sigma| / allowable
  double cpu_s = 0.0;
  long long steps = 0;
};

absl::StatusOr<Measured> Measure(const spec::Scene& scene, const std::vector<double>& p, double allowable_pa) {
  Measured m;
  const std::clock_t start = std::clock();
  const spec::AnalysisReport report = engine::Analyze(scene, p);
  m.cpu_s = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  if (!report.ok()) return absl::InternalError(absl::StrCat("analysis failed: ", report.failure.reason));
  m.steps = static_cast<long long>(report.counters.time_steps);
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    if (!std::holds_alternative<spec::BendingStressOutput>(scene.outputs[k].kind)) continue;
    double peak = 0.0;
    for (const std::vector<double>& node : report.outputs[k].series) {
      for (double v : node) peak = std::max(peak, std::abs(v));
    }
    m.peak_ratio.push_back(peak / allowable_pa);
  }
  return m;
}

std::string Ratios(const std::vector<double>& r) {
  std::string out;
  for (size_t i = 0; i < r.size(); ++i) absl::StrAppend(&out, i ? " / " : "", absl::StrFormat("%.3f", r[i]));
  return out;
}

}  // namespace

absl::StatusOr<std::string> FormulationComparisonMarkdown(const std::string& study_file) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(study_file);
  if (!study.ok()) return study.status();
  auto* linkage = std::get_if<spec::LinkageModel>(&study->scene.model);
  if (linkage == nullptr || study->scene.parameters.size() != 3) {
    return absl::InvalidArgumentError(study_file + ": expected the linkage four-bar with the areas A1, A2, A3");
  }
  // The stress limit of the study's constraints: the benchmark's allowable.
  constexpr double kAllowablePa = 2.758e7;
  const std::vector<Design> designs = {{"report's optimum (9.65, 3.92, 2.69) e-4 m^2", {9.65e-4, 3.92e-4, 2.69e-4}},
                                       {"floating-frame optimum, 2.257 kg (9.137, 3.571, 2.801) e-4 m^2",
                                        {9.137e-4, 3.571e-4, 2.801e-4}}};
  spec::Scene floating = study->scene;
  std::get<spec::LinkageModel>(floating.model).flexible_formulation = spec::FlexibleFormulation::kFloatingFrame;
  spec::Scene corotational = study->scene;
  std::get<spec::LinkageModel>(corotational.model).flexible_formulation = spec::FlexibleFormulation::kCorotational;
  std::string table =
      "| design | floating frame: peak / allowable (crank / coupler / rocker) | co-rotational | coupler, "
      "co-rotational / floating | CPU per analysis, floating | co-rotational | steps, floating / co-rotational |\n"
      "|---|---|---|---:|---:|---:|---|\n";
  for (const Design& d : designs) {
    const std::vector<double>& p = d.areas_m2;
    absl::StatusOr<Measured> f = Measure(floating, p, kAllowablePa);
    if (!f.ok()) return f.status();
    absl::StatusOr<Measured> c = Measure(corotational, p, kAllowablePa);
    if (!c.ok()) return c.status();
    absl::StrAppend(&table, absl::StrFormat("| %s | %s | %s | %.3f | %.2f s | %.2f s | %lld / %lld |\n", d.name,
                                            Ratios(f->peak_ratio), Ratios(c->peak_ratio),
                                            c->peak_ratio[1] / f->peak_ratio[1], f->cpu_s, c->cpu_s, f->steps,
                                            c->steps));
  }
  return absl::StrCat(
      "## Flexible-link formulations\n\n"
      "The elastic four-bar's scene (`",
      study_file,
      "`, its grid and tolerances) analysed once per design in each formulation of its flexible links "
      "(docs/physics.md section 3): the floating frame (small elastic motion on the rigid one, the scene's default "
      "and the published results' model) and co-rotational beam elements "
      "(`flexible_formulation: FLEXIBLE_FORMULATION_COROTATIONAL`, forward dynamics with IDAS). Peak |stress| over "
      "the 7 stations of each link and the grid's instants, over the allowable 27.58 MPa; CPU of one analysis on "
      "this machine.\n\n",
      table,
      "\nThe co-rotational model agrees with an independent co-rotational model of the same mechanism to 0.7 % "
      "(docs/physics.md section 6); the floating frame leaves out the second-order frame terms and so underrates "
      "the coupler's peak. Its optimum is the published one (docs/results.md); the co-rotational model is the "
      "check.\n\n");
}

}  // namespace mbopt::accuracy
