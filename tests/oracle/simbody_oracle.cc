// C++17, Simbody types only here (see simbody_oracle.h).
#include "tests/oracle/simbody_oracle.h"

#include <chrono>
#include <cmath>
#include <exception>

#include "Simbody.h"

namespace mbopt::oracle {
namespace {

using namespace SimTK;

// A uniform bar along its x axis: only the moment about z matters here.
Body::Rigid Bar(double mass, double length) {
  const double moment = mass * length * length / 12.0;
  return Body::Rigid(MassProperties(mass, Vec3(0), Inertia(Vec3(1e-9, moment, moment))));
}

// Steps `integrator` to each time and records `read(state)`.
template <class Read>
OracleRun Record(MultibodySystem& system, State& state, double accuracy, const std::vector<double>& times, Read read) {
  OracleRun run;
  RungeKuttaMersonIntegrator integrator(system);
  integrator.setAccuracy(accuracy);
  integrator.setConstraintTolerance(accuracy * 1e-2);
  TimeStepper stepper(system, integrator);
  stepper.initialize(state);
  for (double t : times) {
    if (t > 0.0) stepper.stepTo(t);
    const State& s = integrator.getState();
    system.realize(s, Stage::Position);
    run.values.push_back(read(s));
  }
  run.ok = true;
  return run;
}

}  // namespace

OracleRun SimulateDoublePendulum(const DoublePendulum& p, const std::vector<double>& times, double accuracy) {
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    Force::UniformGravity gravity(forces, matter, Vec3(0, -p.g, 0));
    MobilizedBody::Pin upper(matter.Ground(), Transform(), Bar(p.m1, p.l1), Transform(Vec3(-p.l1 / 2, 0, 0)));
    MobilizedBody::Pin lower(upper, Transform(Vec3(p.l1 / 2, 0, 0)), Bar(p.m2, p.l2), Transform(Vec3(-p.l2 / 2, 0, 0)));
    State state = system.realizeTopology();
    upper.setAngle(state, p.phi1);
    lower.setAngle(state, p.phi2 - p.phi1);
    return Record(system, state, accuracy, times, [&](const State& s) {
      return std::vector<double>{upper.getAngle(s), upper.getAngle(s) + lower.getAngle(s)};
    });
  } catch (const std::exception& e) {
    return OracleRun{false, e.what(), {}};
  }
}

OracleRun SimulateFourBar(const FourBar& p, const std::vector<double>& times, double accuracy) {
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    Force::UniformGravity gravity(forces, matter, Vec3(0, -p.g, 0));
    MobilizedBody::Pin crank(matter.Ground(), Transform(), Bar(p.m_a, p.a), Transform(Vec3(-p.a / 2, 0, 0)));
    MobilizedBody::Pin coupler(crank, Transform(Vec3(p.a / 2, 0, 0)), Bar(p.m_b, p.b), Transform(Vec3(-p.b / 2, 0, 0)));
    MobilizedBody::Pin rocker(matter.Ground(), Transform(Vec3(p.d, 0, 0)), Bar(p.m_c, p.c),
                              Transform(Vec3(-p.c / 2, 0, 0)));
    // The loop closes at C: the coupler's end in two planes of the rocker
    // (a Ball would add a redundant equation in z).
    Constraint::PointInPlane close_x(rocker, UnitVec3(1, 0, 0), p.c / 2, coupler, Vec3(p.b / 2, 0, 0));
    Constraint::PointInPlane close_y(rocker, UnitVec3(0, 1, 0), 0.0, coupler, Vec3(p.b / 2, 0, 0));
    State state = system.realizeTopology();
    // Initial guesses above the ground line, from the closed-form position.
    const double bx = p.a * std::cos(p.theta), by = p.a * std::sin(p.theta);
    const double ex = p.d - bx, ey = -by, e = std::hypot(ex, ey);
    const double alpha = std::acos((p.b * p.b + e * e - p.c * p.c) / (2 * p.b * e));
    const double coupler_angle = std::atan2(ey, ex) + alpha;
    const double cx = bx + p.b * std::cos(coupler_angle), cy = by + p.b * std::sin(coupler_angle);
    crank.setAngle(state, p.theta);
    coupler.setAngle(state, coupler_angle - p.theta);
    rocker.setAngle(state, std::atan2(cy, cx - p.d));
    Assembler assembler(system);
    assembler.lockMobilizer(crank);
    assembler.setAccuracy(1e-12);
    assembler.assemble(state);
    return Record(system, state, accuracy, times, [&](const State& s) { return std::vector<double>{crank.getAngle(s)}; });
  } catch (const std::exception& e) {
    return OracleRun{false, e.what(), {}};
  }
}

OracleRun SimulateSliderCrank(const SliderCrank& p, const std::vector<double>& times, double accuracy) {
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    MobilizedBody::Pin crank(matter.Ground(), Transform(),
                             Body::Rigid(MassProperties(p.m_crank, Vec3(0), Inertia(Vec3(p.j_crank, p.j_crank, p.j_crank)))),
                             Transform());
    MobilizedBody::Slider slider(matter.Ground(), Transform(),
                                 Body::Rigid(MassProperties(p.m_s, Vec3(0), Inertia(Vec3(1e-3)))), Transform());
    MobilizedBody::Pin rod(slider, Transform(), Bar(p.m_rod, p.l), Transform(Vec3(p.l / 2, 0, 0)));
    Constraint::PointInPlane close_x(crank, UnitVec3(1, 0, 0), p.r, rod, Vec3(-p.l / 2, 0, 0));
    Constraint::PointInPlane close_y(crank, UnitVec3(0, 1, 0), 0.0, rod, Vec3(-p.l / 2, 0, 0));
    Force::ConstantForce push(forces, slider, Vec3(0), Vec3(p.f_x, 0, 0));
    State state = system.realizeTopology();
    const double s = p.r * std::sin(p.theta), x = p.r * std::cos(p.theta) + std::sqrt(p.l * p.l - s * s);
    crank.setAngle(state, p.theta);
    slider.setLength(state, x);
    rod.setAngle(state, std::atan2(-s, x - p.r * std::cos(p.theta)));
    Assembler assembler(system);
    assembler.lockMobilizer(crank);
    assembler.setAccuracy(1e-12);
    assembler.assemble(state);
    return Record(system, state, accuracy, times, [&](const State& st) {
      return std::vector<double>{crank.getAngle(st), slider.getLength(st)};
    });
  } catch (const std::exception& e) {
    return OracleRun{false, e.what(), {}};
  }
}

OracleRun SimulateTenBodyChain(const TenBodyChain& p, const std::vector<double>& times, double accuracy,
                               double* wall_seconds) {
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    Force::UniformGravity gravity(forces, matter, Vec3(0, -p.g, 0));
    std::vector<MobilizedBody::Pin> rockers;
    for (int i = 0; i < 5; ++i) {
      rockers.emplace_back(matter.Ground(), Transform(Vec3(i, 0, 0)), Bar(1.0, 1.0), Transform(Vec3(-0.5, 0, 0)));
    }
    std::vector<MobilizedBody::Pin> couplers;
    std::vector<Constraint::PointInPlane> closures;
    for (int j = 0; j < 4; ++j) {
      couplers.emplace_back(rockers[static_cast<size_t>(j)], Transform(Vec3(0.5, 0, 0)), Bar(1.0, 1.0),
                            Transform(Vec3(-0.5, 0, 0)));
      MobilizedBody& next = rockers[static_cast<size_t>(j + 1)];
      closures.emplace_back(next, UnitVec3(1, 0, 0), 0.5, couplers.back(), Vec3(0.5, 0, 0));
      closures.emplace_back(next, UnitVec3(0, 1, 0), 0.0, couplers.back(), Vec3(0.5, 0, 0));
    }
    MobilizedBody::Pin pendulum(rockers.back(), Transform(Vec3(0.5, 0, 0)), Bar(0.5, 0.6), Transform(Vec3(-0.3, 0, 0)));
    State state = system.realizeTopology();
    for (auto& r : rockers) r.setAngle(state, p.theta);
    for (auto& c : couplers) c.setAngle(state, -p.theta);  // horizontal
    pendulum.setAngle(state, p.pendulum_angle - p.theta);
    system.realize(state, Stage::Position);
    const auto start = std::chrono::steady_clock::now();
    OracleRun run = Record(system, state, accuracy, times, [&](const State& s) {
      return std::vector<double>{rockers.front().getAngle(s), rockers.back().getAngle(s) + pendulum.getAngle(s)};
    });
    if (wall_seconds != nullptr) {
      *wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    return run;
  } catch (const std::exception& e) {
    return OracleRun{false, e.what(), {}};
  }
}

}  // namespace mbopt::oracle
