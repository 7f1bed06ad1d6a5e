// The one-body scene the spec tests load and break one piece at a time:
// a body on a spring and damper over a cosine bump, outputs x (the spring's
// deflection) and acc, 11 instants from 0 to 1 s, parameters k = 100 N/m
// and mass = 2 kg.
#pragma once

#include <string>

namespace mbopt::testing {

inline constexpr char kOscillatorScene[] = R"pb(name: "oscillator"
parameters { name: "k" value: 100 unit: "N/m" }
parameters { name: "mass" value: 2 unit: "kg" }
lumped {
  bodies { name: "body" mass_kg { param: "mass" } dofs: DOF_Y }
  elements {
    name: "spring"
    a { body: "body" }
    b { input: "road" }
    direction { y { value: 1 } }
    stiffness_n_per_m { param: "k" }
    damping_n_s_per_m { value: 0.5 }
  }
  inputs {
    name: "road"
    cosine_bump {
      height_m { value: 0.01 }
      length_m { value: 1 }
      speed_m_per_s { value: 2 }
      start_time_s { value: 0.1 }
    }
    direction { y { value: 1 } }
  }
}
outputs { name: "x" element_deflection { element: "spring" } }
outputs { name: "acc" body_acceleration { body: "body" axis: AXIS_Y } }
time_grid { start_s: 0 end_s: 1 points: 11 }
)pb";

// The oscillator with two more parameters, u = 0.5 and v = 2, that no
// element uses: studies whose responses make them the problem, on a cheap
// analysis. Written as "carrier.scene.textproto" by the tests using it.
inline std::string CarrierScene() {
  std::string scene = kOscillatorScene;
  const std::string after = "parameters { name: \"mass\" value: 2 unit: \"kg\" }\n";
  scene.insert(scene.find(after) + after.size(), "parameters { name: \"u\" value: 0.5 }\nparameters { name: \"v\" value: 2 }\n");
  return scene;
}

// maximize 3 - (u - 1)^2 - (v + 2)^2 on the carrier scene: the maximum 3 at
// u = 1, v = -2.
inline constexpr char kHillStudy[] = R"pb(name: "hill"
scene_file: "carrier.scene.textproto"
variables { name: "u" parameter: "u" lower: -2 upper: 2 }
variables { name: "v" parameter: "v" lower: -3 upper: 3 }
responses { name: "hill" expr: "3 - (u - 1)^2 - (v + 2)^2" }
objective { maximize: "hill" }
optimizer { convergence_objective_tolerance: 1e-6 max_cycles: 200 }
)pb";

}  // namespace mbopt::testing
