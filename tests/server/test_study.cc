#include "tests/server/test_study.h"

#include <google/protobuf/text_format.h>

#include "common/check.h"
#include "common/status_macros.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "spec/study_gradients.h"

namespace mbopt::testing {

v1::Study OscillatorStudy(const std::string& name) {
  constexpr const char* kText = R"pb(
    scene {
      name: "oscillator"
      parameters { name: "k" value: 3000 unit: "N/m" }
      parameters { name: "c" value: 200 unit: "N s/m" }
      parameters { name: "m" value: 10 unit: "kg" }
      lumped {
        bodies {
          name: "mass"
          mass_kg { param: "m" }
          inertia_kg_m2 { value: 1 }
          position_m { x { value: 0 } y { value: 0 } }
          dofs: DOF_Y
        }
        elements {
          name: "spring"
          a { body: "mass" }
          b { ground: true }
          direction { x { value: 0 } y { value: 1 } }
          stiffness_n_per_m { param: "k" }
          damping_n_s_per_m { param: "c" }
        }
      }
      outputs { name: "defl" element_deflection { element: "spring" } }
      outputs { name: "acc" body_acceleration { body: "mass" axis: AXIS_Y } }
      time_grid { start_s: 1 end_s: 1 points: 1 }
    }
    variables { name: "x1" parameter: "k" scale: 1000 initial: 3 lower: 0.1 upper: 10 }
    variables { name: "x2" parameter: "c" scale: 100 initial: 2 lower: 0.1 upper: 10 }
    objective { minimize: "defl" }
    constraints { name: "acc_min" output: "acc" reduction: REDUCTION_MIN limit: 2 }
    optimizer { max_cycles: 40 }
  )pb";
  v1::Study study;
  MBOPT_CHECK(google::protobuf::TextFormat::ParseFromString(kText, &study), "test study does not parse");
  study.set_name(name);
  return study;
}

absl::StatusOr<FakeValues> EvaluateAnalytically(const v1::Study& proto, const std::vector<double>& x) {
  MBOPT_ASSIGN_OR_RETURN(spec::Study study, spec::io::StudyFromProto(proto, "test study"));
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(study));
  const std::vector<std::vector<double>> defl = {{x[0] * x[0] + x[1] * x[1]}};
  const std::vector<std::vector<double>> acc = {{x[0] + x[1]}};
  std::vector<const std::vector<std::vector<double>>*> outputs(study.scene.outputs.size(), nullptr);
  outputs[static_cast<size_t>(study.scene.FindOutput("defl"))] = &defl;
  outputs[static_cast<size_t>(study.scene.FindOutput("acc"))] = &acc;
  MBOPT_ASSIGN_OR_RETURN(spec::StudyValues values, spec::ComputeStudyValues(study, layout, outputs));
  return FakeValues{values.objective_terms, values.constraint_values};
}

v1::Study OscillatorStudyWithSensitivities(const std::string& name) {
  v1::Study study = OscillatorStudy(name);
  study.mutable_optimizer()->set_sensitivity(v1::SENSITIVITY_METHOD_SIMULATOR);
  return study;
}

absl::StatusOr<FakeGradients> GradientsAnalytically(const v1::Study& proto, const std::vector<double>& x) {
  MBOPT_ASSIGN_OR_RETURN(spec::Study study, spec::io::StudyFromProto(proto, "test study"));
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(study));
  const size_t defl_index = static_cast<size_t>(study.scene.FindOutput("defl"));
  const size_t acc_index = static_cast<size_t>(study.scene.FindOutput("acc"));
  using Series = std::vector<std::vector<double>>;
  const Series defl = {{x[0] * x[0] + x[1] * x[1]}};
  const Series acc = {{x[0] + x[1]}};
  std::vector<const Series*> outputs(study.scene.outputs.size(), nullptr);
  outputs[defl_index] = &defl;
  outputs[acc_index] = &acc;
  // d output / d p_si = (d output / d x_i) / (d p_si / d x_i).
  const std::vector<double> per_x = spec::ParameterSiPerScaledVariable(study);
  std::vector<Series> d_defl, d_acc;
  for (size_t i = 0; i < 2; ++i) {
    d_defl.push_back({{2.0 * x[i] / per_x[i]}});
    d_acc.push_back({{1.0 / per_x[i]}});
  }
  std::vector<std::vector<const Series*>> derivatives(2, std::vector<const Series*>(outputs.size(), nullptr));
  for (size_t i = 0; i < 2; ++i) {
    derivatives[i][defl_index] = &d_defl[i];
    derivatives[i][acc_index] = &d_acc[i];
  }
  MBOPT_ASSIGN_OR_RETURN(spec::StudyGradients gradients,
                         spec::ComputeStudyGradients(study, layout, outputs, derivatives));
  FakeGradients out;
  for (const auto& row : gradients.objective_terms) {
    out.objective_gradients.insert(out.objective_gradients.end(), row.begin(), row.end());
  }
  for (const auto& row : gradients.constraint_rows) {
    out.constraint_gradients.insert(out.constraint_gradients.end(), row.begin(), row.end());
  }
  return out;
}

}  // namespace mbopt::testing
