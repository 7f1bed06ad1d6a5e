// A linkage scene followed through the multibody front end instant by
// instant, for tests that check the motion and the rigid-bar loads against
// closed forms (the scene analysis reports only the requested outputs).
#pragma once

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "spec/scene.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/linkage_front_end.h"
#include "worker/multibody/linkage_system.h"
#include "worker/multibody/mechanism.h"

namespace mbopt::linkage_testing {

using AtInstant = std::function<void(const multibody::LinkageSystem& system, const multibody::LinkageState& state,
                                     const multibody::RigidBarLoads& loads)>;

// Calls `at` at every instant of `times_s` (ascending, from 0); with
// `loads`, also with the rigid bars' moments and the drive torque.
inline ::testing::AssertionResult FollowLinkage(const spec::Scene& scene, const std::vector<double>& p,
                                                const std::vector<double>& times_s, bool loads,
                                                const AtInstant& at) {
  auto sys = multibody::ResolveLinkage(std::get<spec::LinkageModel>(scene.model), scene.effects, p);
  if (!sys.ok()) return ::testing::AssertionFailure() << sys.status();
  const multibody::CompiledLinkage compiled = multibody::CompileLinkage(*sys);
  const multibody::Mechanism mechanism(compiled.model);
  const multibody::Assembly assembled = multibody::Assemble(mechanism, 0.0);
  if (!assembled.failure.ok()) return ::testing::AssertionFailure() << assembled.failure.reason;
  multibody::KinematicOptions options;
  options.inverse_dynamics = loads;
  multibody::KinematicCounters counters;
  multibody::LinkageState state;
  multibody::RigidBarLoads bar_loads;
  const spec::AnalysisFailure f = multibody::RunKinematics(
      mechanism, assembled.q, times_s, options,
      [&](const multibody::MotionSample& s) {
        multibody::ToLinkageState(mechanism, compiled, s, &state);
        if (loads) multibody::RigidBarMoments(*sys, mechanism, compiled, s, state, &bar_loads);
        at(*sys, state, bar_loads);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  if (!f.ok()) return ::testing::AssertionFailure() << f.reason;
  return ::testing::AssertionSuccess();
}

}  // namespace mbopt::linkage_testing
