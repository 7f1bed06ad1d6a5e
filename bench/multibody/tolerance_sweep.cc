// What each integration tolerance costs and buys on a multibody scene
// (docs/accuracy_multibody.md): the scene analysed at its parameters'
// values at relative tolerances 1e-4 to 1e-10, the absolute tolerance kept
// in the scene's own ratio to it, against a reference at rtol 1e-11. The
// error of a run is, per output, the largest difference from the reference
// over its series and instants divided by the reference's largest
// magnitude; the table gives the worst output's. CPU is the median over
// the repeats of one whole analysis (AnalyzeMultibodyScene).
//
//   build/bench/multibody/bench_multibody_tolerance_sweep [--repeats=3] SCENE_FILE...
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "spec/io/study_io.h"
#include "worker/multibody/scene_analysis.h"

namespace {

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Sweep {
  mbopt::spec::AnalysisReport report;
  double cpu_s = 0.0;
};

Sweep Analyze(mbopt::spec::Scene scene, const std::vector<double>& values, double relative_tolerance,
              double absolute_per_relative, int repeats) {
  scene.integrator.relative_tolerance = relative_tolerance;
  scene.integrator.absolute_tolerance = relative_tolerance * absolute_per_relative;
  Sweep sweep;
  std::vector<double> cpu;
  for (int r = 0; r < repeats; ++r) {
    const double start = CpuSeconds();
    sweep.report = mbopt::multibody::AnalyzeMultibodyScene(scene, values);
    cpu.push_back(CpuSeconds() - start);
    if (!sweep.report.ok()) break;
  }
  std::sort(cpu.begin(), cpu.end());
  sweep.cpu_s = cpu[cpu.size() / 2];
  return sweep;
}

// The worst output's error relative to its reference's largest magnitude,
// and that output's name.
std::pair<double, std::string> WorstRelativeError(const mbopt::spec::AnalysisReport& run,
                                                  const mbopt::spec::AnalysisReport& reference) {
  std::pair<double, std::string> worst{0.0, ""};
  for (size_t k = 0; k < reference.outputs.size(); ++k) {
    double scale = 0.0, difference = 0.0;
    for (size_t s = 0; s < reference.outputs[k].series.size(); ++s) {
      for (size_t i = 0; i < reference.outputs[k].series[s].size(); ++i) {
        const double ref = reference.outputs[k].series[s][i];
        scale = std::max(scale, std::abs(ref));
        difference = std::max(difference, std::abs(run.outputs[k].series[s][i] - ref));
      }
    }
    const double relative = scale > 0.0 ? difference / scale : difference;
    if (relative >= worst.first) worst = {relative, reference.outputs[k].name};
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--repeats=", 0) == 0 && std::atoi(a.c_str() + 10) > 0) {
      repeats = std::atoi(a.c_str() + 10);
    } else if (a.rfind("--", 0) == 0) {
      std::fprintf(stderr, "unknown option '%s' (expected --repeats=N > 0)\n", a.c_str());
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: %s [--repeats=N] SCENE_FILE...\n", argv[0]);
    return 2;
  }
  for (const std::string& file : files) {
    absl::StatusOr<mbopt::spec::Scene> scene = mbopt::spec::io::LoadSceneFile(file);
    if (!scene.ok()) {
      std::fprintf(stderr, "%s: %s\n", file.c_str(), std::string(scene.status().message()).c_str());
      return 1;
    }
    std::vector<double> values;
    for (const mbopt::spec::Parameter& p : scene->parameters) values.push_back(p.value_si);
    const double absolute_per_relative = scene->integrator.absolute_tolerance / scene->integrator.relative_tolerance;
    std::printf("== %s (scene: rtol %g, atol %g)\n", file.c_str(), scene->integrator.relative_tolerance,
                scene->integrator.absolute_tolerance);
    const Sweep reference = Analyze(*scene, values, 1e-11, absolute_per_relative, 1);
    if (!reference.report.ok()) {
      std::printf("reference at rtol 1e-11 failed: %s\n", reference.report.failure.reason.c_str());
      continue;
    }
    std::printf("| rtol | atol | worst output error (relative) | output | steps | Newton matrices | CPU |\n");
    for (double rtol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
      const Sweep run = Analyze(*scene, values, rtol, absolute_per_relative, repeats);
      if (!run.report.ok()) {
        std::printf("| %.0e | %.0e | failed: %s | | | | |\n", rtol, rtol * absolute_per_relative,
                    run.report.failure.reason.c_str());
        continue;
      }
      const auto [error, output] = WorstRelativeError(run.report, reference.report);
      std::printf("| %.0e | %.0e | %.2g | %s | %lld | %lld | %.3g s |\n", rtol, rtol * absolute_per_relative, error,
                  output.c_str(), static_cast<long long>(run.report.counters.time_steps),
                  static_cast<long long>(run.report.counters.jacobian_evaluations), run.cpu_s);
    }
    std::printf("reference (rtol 1e-11): %lld steps, %.3g s\n",
                static_cast<long long>(reference.report.counters.time_steps), reference.cpu_s);
    std::fflush(stdout);
  }
  return 0;
}
