// `mbopt validate FILE`: checks a study and its scene as a server would
// (spec/io, then the study's layout) without a server, and prints the
// optimization layout: variables, objective, constraints and their rows.
#include <cstdio>
#include <map>
#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "client/args.h"
#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/study_text.h"
#include "spec/io/design_set_convert.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::client {
namespace {

const char* ModelName(const spec::Scene& scene) {
  if (std::holds_alternative<spec::LinkageModel>(scene.model)) return "linkage";
  if (std::holds_alternative<spec::LumpedModel>(scene.model)) return "lumped";
  if (std::holds_alternative<spec::ExternalModel>(scene.model)) return "external";
  if (std::holds_alternative<spec::FmuModel>(scene.model)) return "fmu";
  if (std::holds_alternative<spec::SpatialModel>(scene.model)) return "spatial";
  return "multibody";
}

std::string OutputName(const spec::Study& study, int output) {
  return output >= 0 && output < study.num_signals() ? study.SignalName(output) : "?";
}

std::string ObjectiveText(const spec::Study& study, const spec::StudyLayout& layout) {
  const spec::Objective& o = study.objective;
  switch (o.form) {
    case spec::Objective::Form::kMinimizeMaxOf:
      return absl::StrFormat("minimize the %s of %s over the grid (%d terms, min-max form)",
                             ReductionName(o.reduction), OutputName(study, o.output),
                             layout.num_objective_terms());
    case spec::Objective::Form::kMinimize:
      return absl::StrFormat("%s the %s of %s%s", o.maximize ? "maximize" : "minimize", ReductionName(o.reduction),
                             OutputName(study, o.output),
                             WindowText(o.window));
    case spec::Objective::Form::kWeightedSum: {
      std::string text = "minimize the weighted sum:";
      for (const spec::WeightedTerm& t : o.sum_terms) {
        text += absl::StrFormat(" %+g x %s of %s%s%s%s", t.weight, ReductionName(t.reduction),
                                OutputName(study, t.output), WindowText(t.window), t.unit.empty() ? "" : " in ",
                                t.unit);
      }
      if (layout.objective_form == spec::ObjectiveForm::kSumOfMax) {
        text += absl::StrFormat(" (%d terms in %d groups, sum-of-maxima form)", layout.num_objective_terms(),
                                static_cast<int>(layout.objective_group_sizes.size()));
      }
      return text;
    }
    case spec::Objective::Form::kMaxOver: {
      std::string text = "minimize the largest of:";
      for (const spec::WeightedTerm& t : o.sum_terms) {
        text += absl::StrFormat(" %s%s of %s%s%s%s;", t.weight != 1.0 ? absl::StrFormat("%g x ", t.weight) : "",
                                ReductionName(t.reduction), OutputName(study, t.output), WindowText(t.window),
                                t.unit.empty() ? "" : " in ", t.unit);
      }
      text.pop_back();
      return text + absl::StrFormat(" (%d terms, min-max form)", layout.num_objective_terms());
    }
    case spec::Objective::Form::kFeasible:
      return "none: find a design that meets every constraint (F = 0; the run ends at the first such design)";
    case spec::Objective::Form::kTargetDistance: {
      std::string text = "distance to targets:";
      for (const spec::TargetTerm& t : o.terms) {
        text += absl::StrFormat(" %s -> %g%s%s", OutputName(study, t.output), t.target,
                                t.unit.empty() ? "" : " ", t.unit);
      }
      return text;
    }
  }
  return "?";
}

}  // namespace

int ValidateCommand(const Args& args) {
  auto parsed = ParseArgs(args, {{}, {}});
  if (!parsed.ok()) return Fail(std::string(parsed.status().message()), kExitBadInput);
  if (parsed->positional.size() != 1) return Fail("usage: mbopt validate STUDY_FILE", kExitBadInput);
  const std::string path = parsed->positional[0];
  // The same two steps as a submission: the file as sent, then the server's
  // own reading of it.
  auto message = spec::io::ReadStudyProto(path);
  if (!message.ok()) return Fail(std::string(message.status().message()), kExitBadInput);
  auto study = spec::io::StudyFromProto(*message, path);
  if (!study.ok()) return Fail(std::string(study.status().message()), kExitBadInput);
  auto layout = spec::MakeStudyLayout(*study);
  if (!layout.ok()) return Fail(std::string(layout.status().message()), kExitBadInput);

  const spec::Scene& scene = study->scene;
  std::printf("study:       %s (%s)\n", study->name.c_str(), path.c_str());
  std::printf("form:        %s\n", spec::io::DescribeStudyForm(*study).c_str());
  std::printf("scene:       %s, %s model, %d instants from %g s to %g s, %zu outputs\n",
              scene.name.c_str(), ModelName(scene), scene.time_grid.points, scene.time_grid.start_s,
              scene.time_grid.end_s, scene.outputs.size());
  std::printf("variables:   %zu\n", study->variables.size());
  for (const spec::DesignVariable& v : study->variables) {
    const spec::Parameter& p = scene.parameters[static_cast<size_t>(v.parameter)];
    const std::string unit = p.unit.empty() ? "" : " " + p.unit;
    std::string sets = p.name;
    for (int also : v.also_sets) sets += "," + scene.parameters[static_cast<size_t>(also)].name;
    std::printf("  %-12s sets %-20s initial %-12g in [%g, %g]%s\n", v.name.c_str(), sets.c_str(),
                v.scale * v.initial, v.scale * v.lower, v.scale * v.upper, unit.c_str());
  }
  if (!study->cases.empty()) {
    std::printf("load cases:  %zu, each analysed at every design point\n", study->cases.size());
    for (const spec::LoadCase& c : study->cases) {
      std::string sets;
      for (const auto& [parameter, value_si] : c.parameter_values_si) {
        const spec::Parameter& p = scene.parameters[static_cast<size_t>(parameter)];
        sets += absl::StrFormat("%s%s = %g%s%s", sets.empty() ? "" : ", ", p.name, value_si / p.si_per_unit,
                                p.unit.empty() ? "" : " ", p.unit);
      }
      std::printf("  %-12s %s\n", c.name.c_str(), sets.empty() ? "(the scene as it is)" : sets.c_str());
    }
  }
  if (!study->responses.empty()) {
    std::printf("responses:   %zu\n", study->responses.size());
    for (size_t r = 0; r < study->responses.size(); ++r) {
      const spec::Response& response = study->responses[r];
      const spec::OutputShape& shape = layout->outputs[static_cast<size_t>(study->num_case_signals()) + r];
      std::printf("  %-12s = %s%s%s (%s)\n", response.name.c_str(), response.expression->text().c_str(),
                  response.dimension == spec::Dimension::kAny ? "" : ", a ",
                  response.dimension == spec::Dimension::kAny ? "" : spec::DimensionName(response.dimension),
                  shape.scalar ? "one value" : absl::StrFormat("%d series of %d instants", shape.series,
                                                               shape.instants).c_str());
    }
  }
  std::printf("objective:   %s\n", ObjectiveText(*study, *layout).c_str());
  std::map<int, int> rows_per_constraint;
  for (const spec::ConstraintRow& row : layout->rows) ++rows_per_constraint[row.constraint];
  // A front's second objective's rows are the objective's, not the constraints'.
  std::printf("constraints: %zu, %d rows\n", study->constraints.size(),
              layout->num_constraints() - static_cast<int>(layout->second_objective_factors.size()));
  for (size_t k = 0; k < study->constraints.size(); ++k) {
    const spec::Constraint& c = study->constraints[k];
    std::string bound;
    if (spec::IsWholeSeriesReduction(c.reduction)) {
      if (c.lower && c.upper) {
        bound = absl::StrFormat("in [%g, %g]", *c.lower, *c.upper);
      } else if (c.upper) {
        bound = absl::StrFormat("<= %g", *c.upper);
      } else if (c.lower) {
        bound = absl::StrFormat(">= %g", *c.lower);
      }
    } else {
      bound = absl::StrFormat("%s %g", c.reduction == spec::Reduction::kMin ? ">=" : "<=", c.limit);
    }
    std::printf("  %-12s %s of %s%s %s%s%s (%d rows)\n", c.name.c_str(), ReductionName(c.reduction),
                OutputName(*study, c.output).c_str(), WindowText(c.window).c_str(), bound.c_str(),
                c.unit.empty() ? "" : " ", c.unit.c_str(), rows_per_constraint[static_cast<int>(k)]);
  }
  std::printf("valid\n");
  return kExitOk;
}

}  // namespace mbopt::client
