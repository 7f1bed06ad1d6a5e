// C++17, Simbody types only here (see simbody_oracle.h).
#include "tests/oracle/simbody_oracle.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <memory>

#include "Simbody.h"

namespace mbopt::oracle {
namespace {

using namespace SimTK;

// A uniform bar along its x axis: only the moment about z matters here.
Body::Rigid Bar(double mass, double length) {
  const double moment = mass * length * length / 12.0;
  return Body::Rigid(MassProperties(mass, Vec3(0), Inertia(Vec3(1e-9, moment, moment))));
}

std::string g_integrator = "rkm";

std::unique_ptr<Integrator> MakeIntegrator(MultibodySystem& system) {
  if (g_integrator == "cpodes") {
    return std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
  }
  return std::make_unique<RungeKuttaMersonIntegrator>(system);
}

// Steps the chosen integrator to each time and records `read(state)`; the
// CPU time and steps of the stepping go to the run.
template <class Read>
OracleRun Record(MultibodySystem& system, State& state, double accuracy, const std::vector<double>& times, Read read) {
  OracleRun run;
  const std::clock_t start = std::clock();
  std::unique_ptr<Integrator> integrator = MakeIntegrator(system);
  integrator->setAccuracy(accuracy);
  integrator->setConstraintTolerance(accuracy * 1e-2);
  TimeStepper stepper(system, *integrator);
  stepper.initialize(state);
  for (double t : times) {
    if (t > 0.0) stepper.stepTo(t);
    const State& s = integrator->getState();
    system.realize(s, Stage::Position);
    run.values.push_back(read(s));
  }
  run.cpu_seconds = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  run.steps = integrator->getNumStepsTaken();
  run.ok = true;
  return run;
}

}  // namespace

bool UseIntegrator(const std::string& name) {
  if (name != "rkm" && name != "cpodes") return false;
  g_integrator = name;
  return true;
}

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

OracleRun SimulateRodChain(int rods, const std::vector<double>& times, double accuracy) {
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    Force::UniformGravity gravity(forces, matter, Vec3(0, -9.81, 0));
    // A tree of pins from the first ground pin; the last rod's end closes
    // on the second ground pin in two planes of the ground.
    std::vector<MobilizedBody::Pin> pins;
    pins.reserve(static_cast<size_t>(rods));
    for (int i = 0; i < rods; ++i) {
      MobilizedBody& parent = i == 0 ? static_cast<MobilizedBody&>(matter.updGround()) : pins.back();
      pins.emplace_back(parent, Transform(Vec3(i == 0 ? 0.0 : 0.5, 0, 0)), Bar(1.0, 1.0), Transform(Vec3(-0.5, 0, 0)));
    }
    Constraint::PointInPlane close_x(matter.updGround(), UnitVec3(1, 0, 0), rods - 2.0, pins.back(), Vec3(0.5, 0, 0));
    Constraint::PointInPlane close_y(matter.updGround(), UnitVec3(0, 1, 0), 0.0, pins.back(), Vec3(0.5, 0, 0));
    State state = system.realizeTopology();
    const double slope = Pi / 3;
    pins.front().setAngle(state, -slope);
    pins[2].setAngle(state, slope);
    pins[static_cast<size_t>(rods - 2)].setAngle(state, slope);
    return Record(system, state, accuracy, times, [&](const State& s) {
      std::vector<double> angles;
      double sum = 0.0;
      for (const MobilizedBody::Pin& pin : pins) angles.push_back(sum += pin.getAngle(s));
      return angles;
    });
  } catch (const std::exception& e) {
    return OracleRun{false, e.what(), {}};
  }
}

OracleRun SimulateAndrews(const std::vector<double>& times, double accuracy) {
  // The published data (m, kg, kg m^2, N/m, N m).
  const double m1 = .04325, m2 = .00365, m3 = .02373, m4 = .00706, m5 = .07050, m6 = .00706, m7 = .05498;
  const double i1 = 2.194e-6, i2 = 4.410e-7, i3 = 5.255e-6, i4 = 5.667e-7, i5 = 1.169e-5, i6 = 5.667e-7,
               i7 = 1.912e-5;
  const double xa = -.06934, ya = -.00227, xb = -.03635, yb = .03273, xc = .014, yc = .072;
  const double d = .028, da = .0115, e = .02, ea = .01421, rr = .007, ra = .00092, ss = .035, sa = .01874,
               sb = .01043, sc = .018, sd = .02, ta = .02308, tb = .00916, u = .04, ua = .01228, ub = .00449,
               zf = .02, zt = .04, fa = .01421;
  const double c0 = 4530, l0 = .07785, mom = .033;
  try {
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    // Each body's frame at its centre of mass, as the published mass matrix
    // puts it; each pin's frames at the pin, unrotated, so that a pin's
    // angle is the published relative angle.
    auto rigid = [](double mass, double moment) {
      return Body::Rigid(MassProperties(mass, Vec3(0), Inertia(Vec3(moment, moment, moment))));
    };
    MobilizedBody& ground = matter.updGround();
    MobilizedBody::Pin crank(ground, Transform(), rigid(m1, i1), Transform(Vec3(-ra, 0, 0)));
    MobilizedBody::Pin coupler(crank, Transform(Vec3(rr - ra, 0, 0)), rigid(m2, i2), Transform(Vec3(da, 0, 0)));
    MobilizedBody::Pin rocker_b(ground, Transform(Vec3(xb, yb, 0)), rigid(m3, i3), Transform(Vec3(-sa, sb, 0)));
    MobilizedBody::Pin rocker_a(ground, Transform(Vec3(xa, ya, 0)), rigid(m5, i5), Transform(Vec3(-ta, -tb, 0)));
    MobilizedBody::Pin link_e(rocker_a, Transform(Vec3(zt - ta, -tb, 0)), rigid(m4, i4), Transform(Vec3(0, e - ea, 0)));
    MobilizedBody::Pin rocker_c(ground, Transform(Vec3(xa, ya, 0)), rigid(m7, i7), Transform(Vec3(-ua, -ub, 0)));
    MobilizedBody::Pin link_g(rocker_c, Transform(Vec3(-ua, -u - ub, 0)), rigid(m6, i6),
                              Transform(Vec3(fa - zf, 0, 0)));
    // Rocker B, link E and link G meet the coupler's end Q.
    const Vec3 coupler_q(da - d, 0, 0);
    std::vector<Constraint::PointInPlane> closures;
    const std::pair<MobilizedBody*, Vec3> at_q[] = {
        {&rocker_b, Vec3(-sa, sb - ss, 0)}, {&link_e, Vec3(0, -ea, 0)}, {&link_g, Vec3(fa, 0, 0)}};
    for (const auto& [body, station] : at_q) {
      closures.emplace_back(coupler, UnitVec3(1, 0, 0), coupler_q[0], *body, station);
      closures.emplace_back(coupler, UnitVec3(0, 1, 0), 0.0, *body, station);
    }
    Force::TwoPointLinearSpring spring(forces, rocker_b, Vec3(sd - sa, sb - sc, 0), ground, Vec3(xc, yc, 0), c0, l0);
    Force::MobilityConstantForce drive(forces, crank, mom);
    State state = system.realizeTopology();
    // The published consistent initial angles.
    crank.setAngle(state, -0.0617138900142764496358948458001);
    coupler.setAngle(state, 0.0);
    rocker_b.setAngle(state, 0.455279819163070380255912382449);
    link_e.setAngle(state, 0.222668390165885884674473185609);
    rocker_a.setAngle(state, 0.487364979543842550225598953530);
    link_g.setAngle(state, -0.222668390165885884674473185609);
    rocker_c.setAngle(state, 1.23054744454982119249735015568);
    return Record(system, state, accuracy, times, [&](const State& s) {
      return std::vector<double>{crank.getAngle(s),    coupler.getAngle(s), rocker_b.getAngle(s),
                                 link_e.getAngle(s),   rocker_a.getAngle(s), link_g.getAngle(s),
                                 rocker_c.getAngle(s)};
    });
  } catch (const std::exception& ex) {
    return OracleRun{false, ex.what(), {}};
  }
}

}  // namespace mbopt::oracle
