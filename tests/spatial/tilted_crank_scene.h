// A fully driven spatial scene whose drawing has a closed form, shared by
// the drawing's tests in world axes (tests/spatial) and in the report's
// views (tests/report).
//
// A crank turns about a ground axis through c = (0, 0, 0.1) m along
// n = (0, -1, 1) / sqrt(2) (the ground marker turned 45 deg about x) at
// theta = pi t; its pin sits 0.2 m along its body x axis, so
//   pin(t) = c + 0.2 (cos theta, sin theta / sqrt(2), sin theta / sqrt(2)).
// A block slides on a rail along the crank's body x axis through the hub,
// its slide driven as s = 0.05 + 0.1 t, so
//   block(t) = c + s (cos theta, sin theta / sqrt(2), sin theta / sqrt(2)),
// and the rail's axis points along (cos theta, sin theta / sqrt(2),
// sin theta / sqrt(2)). A force of the block's body z axis turns with it,
// along Rot(n, theta) z = (-sin theta / sqrt(2), -(1 - cos theta) / 2,
// (1 + cos theta) / 2).
#pragma once

namespace mbopt::testing {

inline constexpr char kTiltedCrankScene[] = R"pb(
  name: "tilted crank"
  spatial {
    ground_markers {
      name: "axis"
      position_m { z { value: 0.1 } }
      orientation { axis_angle { axis { x { value: 1 } } angle_deg: 45 } }
    }
    bodies {
      name: "crank"
      mass_kg { value: 1 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.01 } } }
      position_m { z { value: 0.1 } }
      markers { name: "hub" orientation { axis_angle { axis { x { value: 1 } } angle_deg: 45 } } }
      markers { name: "pin" position_m { x { value: 0.2 } } }
      markers { name: "rail" orientation { axis_angle { axis { y { value: 1 } } angle_deg: 90 } } }
    }
    bodies {
      name: "block"
      mass_kg { value: 0.5 }
      principal_inertia { moments_kg_m2 { x { value: 0.001 } y { value: 0.001 } z { value: 0.001 } } }
      position_m { x { value: 0.05 } z { value: 0.1 } }
      markers { name: "slot" orientation { axis_angle { axis { y { value: 1 } } angle_deg: 90 } } }
    }
    joints { name: "bearing" kind: SPATIAL_JOINT_REVOLUTE a: "ground.axis" b: "crank.hub" }
    joints { name: "rail" kind: SPATIAL_JOINT_PRISMATIC a: "crank.rail" b: "block.slot" }
    drivers { joint: "bearing" constant_rate { rate { value: 3.141592653589793 } } }
    drivers { joint: "rail" slide: true polynomial { coefficients { value: 0.05 } coefficients { value: 0.1 } } }
    point_forces { name: "push" at: "block.slot" force_n { z { value: 10 } } axes: SPATIAL_LOAD_BODY_AXES }
  }
  time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";

}  // namespace mbopt::testing
