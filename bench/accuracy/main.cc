// mbopt_accuracy: the accuracy-versus-time sweep (docs/accuracy.md). For each
// reference problem it optimizes the study once per setting of one accuracy
// knob, re-checks every found design on a fine model, and writes a table, a
// Pareto plot (SVG) and a recommendation derived from the measurements.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "bench/accuracy/accuracy_report.h"
#include "bench/accuracy/formulation_comparison.h"
#include "bench/accuracy/pareto_svg.h"
#include "bench/accuracy/sweep_plan.h"
#include "bench/accuracy/sweep_run.h"
#include "common/status_macros.h"
#include "tests/testing/local_run/local_run.h"
#include "spec/io/study_io.h"

namespace mbopt::accuracy {
namespace {

const char kUsage[] =
    "usage: mbopt_accuracy [--problem vehicle|fourbar_rigid|fourbar_elastic|landing_gear|formulations|all]\n"
    "                      [--out FILE] [--svg-dir DIR]\n"
    "  Run from the repository root. Default: all problems, Markdown to stdout, no plots.\n";

constexpr double kErrorFloor = 1e-6;  // the plot's floor for a zero error

const char kIntro[] = R"(Each problem's study is optimized to its end in this process (the SLP core, CLP and the
analysis engine: `local_run::RunStudyLocally`) once per setting, varying **one knob at a time**
around the study's own settings ("default"): the time grid, the integrator's relative tolerance
(the absolute tolerance follows at 1e-3 times it), the elements per flexible link, rigid links
instead of elastic ones, the finite-difference scheme and relative step of the optimizer, and
(where the scene has them) gradients from the simulator's sensitivity equations instead.
For every setting:

- **F found**: the objective at the design the run ended with, as that run computed it.
- **error vs F_ref**: |F - F_ref| / max(|F_ref|, 1 % |F(x0)|), where F_ref is the objective found by
  the tight **reference run** (finest grid, tightest tolerance, finest mesh of the sweep). The
  floor matters only for the landing gear, whose optimum is near zero. F_ref is the SLP's own
  answer on the reference model, so it carries the optimizer's stopping error too (the SLP stops
  when a cycle improves F by less than 0.5 %; docs/comparison.md shows it ending about 0.2 %
  above the best known optimum on the vehicle).
- **change vs default**: the same measure against the default run's F: the knob's own effect.
- **F re-checked / true max violation**: the found design analysed once more on the fine
  re-check model (a grid at least as fine as the reference's where the grid matters, the
  reference's tolerance and mesh; named in each problem's first line).
  The violation is the largest normalized constraint value (g - c) / scale, > 0 violated: what
  the design really does between the grid points the optimizer saw.
- **analyses, wall**: what the whole optimization cost (one core, analyses and LPs included).

The plots put wall time against the objective error (log-log); the dashed staircase is the Pareto
front (no other setting is both faster and more accurate); hollow red points are designs whose
re-check violates a constraint by more than 0.5 %; the square is the study's default. Where
labels would overlap, the later ones (off the front) are left out; the tables name every point.
)";

const char kNotMeasured[] = R"md(## Not yet measured

- **Simulator sensitivities on the linkages.** The "sensitivity: simulator (CVODES)" row is the
  vehicle's (a lumped scene, CVODES forward sensitivities inside each analysis: one analysis per
  cycle instead of 1 + n). The linkage scenes (four-bars, landing gear) have no simulator
  sensitivities yet, so their gradients are finite differences only.
- **Knob interactions.** Knobs are varied one at a time; only the recommended combination per
  problem (and, when it fails, its model knobs alone) is run to check it. Other combinations are
  not measured.
- **Timing noise.** Wall times come from one run on a shared 2-core machine (the fastest of
  three for runs under 2 s); differences below about 20 % are not significant.
- **Integrator choice and order limits**, the LP solver's tolerances and the move-limit
  thresholds of METHOD.md section 3 are not part of this sweep.
)md";

// Not a sweep: the two formulations of the elastic four-bar's flexible
// links side by side (formulation_comparison.h).
constexpr char kFormulations[] = "formulations";
constexpr char kElasticFourBarStudy[] = "examples/fourbar/fourbar_elastic.study.textproto";

struct Args {
  std::vector<std::string> problems;
  std::string out;
  std::string svg_dir;
};

// Runs shorter than this are repeated and the fastest wall time kept: on a
// shared machine a single sub-second run is mostly scheduling noise. The
// runs are deterministic, so only the time changes.
constexpr double kRepeatBelowSeconds = 2.0;
constexpr int kRepeats = 3;

absl::StatusOr<SettingResult> TimedRun(const v1::Study& base, const std::string& source, const Setting& s,
                                       const RecheckModel& recheck) {
  std::cerr << source << ": " << s.knob << " " << s.value << " ... ";
  MBOPT_ASSIGN_OR_RETURN(SettingResult r, RunSetting(base, source, s, recheck));
  for (int k = 1; k < kRepeats && r.wall_seconds < kRepeatBelowSeconds; ++k) {
    MBOPT_ASSIGN_OR_RETURN(SettingResult again, RunSetting(base, source, s, recheck));
    r.wall_seconds = std::min(r.wall_seconds, again.wall_seconds);
  }
  std::cerr << absl::StrFormat("F %.6g, %d analyses, %.2f s\n", r.objective, r.analyses, r.wall_seconds);
  return r;
}

absl::StatusOr<ProblemSweep> RunProblem(const SweepPlan& plan, const Acceptance& acceptance,
                                        std::vector<std::string>* why) {
  ProblemSweep sweep;
  sweep.plan = plan;
  MBOPT_ASSIGN_OR_RETURN(v1::Study base, spec::io::ReadStudyProto(plan.study_file));
  for (size_t i = 0; i < plan.initial_override.size() && static_cast<int>(i) < base.variables_size(); ++i) {
    base.mutable_variables(static_cast<int>(i))->set_initial(plan.initial_override[i]);
  }
  MBOPT_ASSIGN_OR_RETURN(RecheckModel recheck, MakeRecheckModel(base, plan.study_file, plan.recheck));
  Eigen::VectorXd x0(recheck.study.variables.size());
  for (size_t i = 0; i < recheck.study.variables.size(); ++i) x0[i] = recheck.study.variables[i].initial;
  MBOPT_ASSIGN_OR_RETURN(engine::StudyEvaluation e0,
                         local_run::EvaluateDesign(recheck.study, recheck.layout, x0));
  if (!e0.ok()) return absl::FailedPreconditionError(absl::StrCat("initial design fails: ", e0.failure.reason));
  sweep.initial_objective = e0.values->objective;
  MBOPT_ASSIGN_OR_RETURN(sweep.reference, TimedRun(base, plan.study_file, plan.reference, recheck));
  for (const Setting& s : plan.settings) {
    MBOPT_ASSIGN_OR_RETURN(SettingResult r, TimedRun(base, plan.study_file, s, recheck));
    sweep.results.push_back(std::move(r));
  }
  Setting model_only;
  const Setting recommended = RecommendedSetting(sweep, acceptance, why, &model_only);
  MBOPT_ASSIGN_OR_RETURN(sweep.recommended, TimedRun(base, plan.study_file, recommended, recheck));
  const SettingResult& r = *sweep.recommended;
  const bool pass = WithinReferenceTolerances(sweep, r, acceptance);
  if (!pass && recommended.value != model_only.value) {
    MBOPT_ASSIGN_OR_RETURN(sweep.fallback, TimedRun(base, plan.study_file, model_only, recheck));
  }
  return sweep;
}

int Main(int argc, char** argv) {
  Args args;
  std::string problem = "all";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--problem" && i + 1 < argc) {
      problem = argv[++i];
    } else if (a == "--out" && i + 1 < argc) {
      args.out = argv[++i];
    } else if (a == "--svg-dir" && i + 1 < argc) {
      args.svg_dir = argv[++i];
    } else {
      std::cerr << kUsage;
      return 2;
    }
  }
  args.problems = problem == "all" ? ProblemNames() : std::vector<std::string>{problem};
  if (problem == "all") args.problems.push_back(kFormulations);
  std::vector<std::string> command(argv, argv + argc);
  command[0] = "mbopt_accuracy";

  const auto start = std::chrono::steady_clock::now();
  const Acceptance acceptance;
  std::string body;
  std::vector<std::string> failed;
  for (const std::string& name : args.problems) {
    if (name == kFormulations) {
      absl::StatusOr<std::string> section = FormulationComparisonMarkdown(kElasticFourBarStudy);
      if (!section.ok()) {
        std::cerr << name << ": " << section.status() << "\n";
        absl::StrAppend(&body, "## Flexible-link formulations\n\nCould not be run: `", section.status().ToString(),
                        "`\n\n");
        failed.push_back(name);
      } else {
        absl::StrAppend(&body, *section);
      }
      continue;
    }
    SweepPlan plan;
    if (!MakeSweepPlan(name, &plan)) {
      std::cerr << "unknown problem " << name << "\n" << kUsage;
      return 2;
    }
    std::vector<std::string> why;
    absl::StatusOr<ProblemSweep> sweep = RunProblem(plan, acceptance, &why);
    if (!sweep.ok()) {
      std::cerr << name << ": " << sweep.status() << "\n";
      absl::StrAppend(&body, "## ", name, "\n\nCould not be run: `", sweep.status().ToString(), "`\n\n");
      failed.push_back(name);
      continue;
    }
    std::string svg_link;
    if (!args.svg_dir.empty()) {
      std::filesystem::create_directories(args.svg_dir);
      const std::filesystem::path svg = std::filesystem::path(args.svg_dir) / absl::StrCat("accuracy_", name, ".svg");
      std::ofstream f(svg);
      f << ParetoSvg(absl::StrCat(name, ": wall time vs objective error"), PlotPoints(*sweep, acceptance),
                     kErrorFloor);
      if (!f) {
        std::cerr << "cannot write " << svg << "\n";
        return 1;
      }
      const std::filesystem::path out_dir =
          args.out.empty() ? std::filesystem::current_path()
                           : std::filesystem::absolute(args.out).parent_path();
      svg_link = std::filesystem::relative(std::filesystem::absolute(svg), out_dir).generic_string();
    }
    absl::StrAppend(&body, ProblemMarkdown(*sweep, acceptance, svg_link, why));
  }
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::string doc = absl::StrCat("# Accuracy versus time\n\nGenerated by\n\n```\n", absl::StrJoin(command, " "),
                                 "\n```\n\nrun from the repository root on the build of deploy/build.sh (RelWithDebInfo, in build/) (",
                                 absl::StrFormat("%.0f", total_s),
                                 " s in all on this machine). Nothing in this file is edited by hand; the multibody scenes measured by hand are in "
                                 "[accuracy_multibody.md](accuracy_multibody.md).\n\n",
                                 kIntro, "\n", body);
  if (!failed.empty()) {
    absl::StrAppend(&doc, "Problems that could not be run: ", absl::StrJoin(failed, ", "), ".\n\n");
  }
  absl::StrAppend(&doc, kNotMeasured);
  if (args.out.empty()) {
    std::cout << doc;
  } else {
    std::ofstream f(args.out);
    f << doc;
    if (!f) {
      std::cerr << "cannot write " << args.out << "\n";
      return 1;
    }
  }
  return failed.empty() ? 0 : 1;
}

}  // namespace
}  // namespace mbopt::accuracy

int main(int argc, char** argv) { return mbopt::accuracy::Main(argc, argv); }
