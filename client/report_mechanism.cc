#include "client/report_mechanism.h"

#include <google/protobuf/text_format.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/report/deflection_scale.h"
#include "client/temp_dir.h"
#include "client/worker_draw.h"
#include "spec/io/study_io.h"

namespace mbopt::client {
namespace {

constexpr char kNoFinalDesign[] = "The job has no final design yet: only the initial design is drawn.";

// `--set` for every design variable at scaled design x: 17 digits, the
// design the job reached bit for bit.
std::vector<std::string> DesignSets(const spec::Study& study, const std::vector<double>& x) {
  std::vector<std::string> sets;
  for (size_t k = 0; k < x.size(); ++k) sets.push_back(absl::StrFormat("%s=%.17g", study.variables[k].name, x[k]));
  return sets;
}

}  // namespace

void AddMechanismDrawings(const v1::GetJobResponse& job, report::ReportData* data, double deflection_scale) {
  report::MechanismDrawings& mechanism = data->mechanism;
  const v1::Scene::ModelCase kind = job.study().scene().model_case();
  if (kind != v1::Scene::kMultibody && kind != v1::Scene::kLinkage && kind != v1::Scene::kLumped &&
      kind != v1::Scene::kSpatial) {
    mechanism.note = "Only multibody, linkage, spatial and lumped scenes are drawn; this job's scene is of another kind.";
    return;
  }
  absl::StatusOr<spec::Study> loaded = spec::io::StudyFromProto(job.study(), "the job's study");
  if (!loaded.ok()) {
    mechanism.note = "The job's study could not be read: " + std::string(loaded.status().message());
    return;
  }
  const spec::Study& study = *loaded;
  const v1::JobSummary& summary = job.summary();
  absl::StatusOr<std::string> worker = FindWorkerProgram();
  if (!worker.ok()) {
    mechanism.note = "The mechanism cannot be drawn here: " + std::string(worker.status().message());
    return;
  }
  std::vector<double> x0, x_final;
  for (const spec::DesignVariable& v : study.variables) x0.push_back(v.initial);
  const bool has_final = job.cycles_size() > 0 && summary.design_size() == static_cast<int>(study.variables.size());
  if (has_final) {
    for (int k = 0; k < summary.design_size(); ++k) {
      x_final.push_back(summary.design(k) / study.variables[static_cast<size_t>(k)].scale);
    }
  }
  TempDir dir;
  std::string text;
  google::protobuf::TextFormat::PrintToString(job.study(), &text);
  const std::string study_path = dir.path() + "/study.study.textproto";
  std::ofstream(study_path) << text;
  // One pair of drawings per load case (the worker sets the case's
  // parameters), or of the scene as it is for a study without cases.
  std::vector<std::string> cases;
  for (const spec::LoadCase& c : study.cases) cases.push_back(c.name);
  if (cases.empty()) cases.emplace_back();
  std::fprintf(stderr, "drawing the mechanism at the initial and the final design%s ...\n",
               study.cases.empty() ? "" : absl::StrFormat(" (%d load cases)", study.cases.size()).c_str());
  for (size_t k = 0; k < cases.size(); ++k) {
    const std::string& name = cases[k];
    report::LoadCaseDrawings drawn;
    drawn.name = name;
    std::vector<std::string> notes;
    const std::string prefix = dir.path() + "/case-" + std::to_string(k);
    absl::StatusOr<spec::SceneDrawing> initial =
        RunWorkerDraw(*worker, study_path, DesignSets(study, x0), prefix + "-initial.pb", name);
    if (initial.ok()) {
      drawn.initial = report::MagnifyDeflection(*std::move(initial), deflection_scale);
    } else {
      notes.push_back(absl::StrCat("The initial design could not be drawn: ", initial.status().message()));
    }
    if (!has_final) {
      // Said once for the whole section when there are cases.
      if (study.cases.empty()) notes.push_back(kNoFinalDesign);
    } else {
      absl::StatusOr<spec::SceneDrawing> final =
          RunWorkerDraw(*worker, study_path, DesignSets(study, x_final), prefix + "-final.pb", name);
      if (final.ok()) {
        drawn.final = report::MagnifyDeflection(*std::move(final), deflection_scale);
      } else {
        notes.push_back(absl::StrCat("The final design could not be drawn: ", final.status().message()));
      }
    }
    for (std::string& note : notes) drawn.note += (drawn.note.empty() ? "" : " ") + note;
    if (study.cases.empty()) {
      mechanism.initial = std::move(drawn.initial);
      mechanism.final = std::move(drawn.final);
      mechanism.note = std::move(drawn.note);
    } else {
      mechanism.cases.push_back(std::move(drawn));
    }
  }
  if (!study.cases.empty() && !has_final) mechanism.note = kNoFinalDesign;
}

}  // namespace mbopt::client
