// Simbody simulating the mechanisms of spatial_oracle.h, as a program of
// its own for the reasons tests/oracle/simbody_oracle.h gives (Simbody 3.7's
// headers are C++17 and its SimTKmath exports an old SUNDIALS' symbols).
//
//   mbopt_simbody_spatial_oracle [--integrator=rkm|cpodes] [--cpu=REPEATS] [--energy]
//       MECHANISM ACCURACY END_S INTERVALS
//
// MECHANISM is double_pendulum (released at rest),
// spinning_double_pendulum, hung_chain or bushing_body (spatial_oracle.h), or
// one of the closed loops of spatial_mechanisms.h: bricard, rssr, cardan,
// spherical_chain, slider_crank (the IFToMM spatial rigid slider-crank).
// The options apply to the closed loops: the integrator (Runge-Kutta-Merson by
// default, or CPodes' BDF), CPU timing (see ClosedLoop) and --energy, which
// appends the total energy (kinetic plus gravity's potential, J) to each
// line. A closed loop becomes a
// tree of mobilizers (each joint whose second body is not yet placed; a
// prismatic joint is a MobilizedBody::Slider along W's z) and
// constraints closing it: Constraint::Ball for a spherical joint, a ball
// and two right angles (Constraint::ConstantAngle) for a revolute one,
// Constraint::PointOnLine. Bodies start with the velocities the mechanism
// gives (each mobilizer's u fitted to its bodies' relative velocity at the
// joint), then projected onto the constraints. Simbody solves its constraint equations with
// rank-revealing factorizations, so a redundant closure (Bricard's) is
// given to it as it is.
//
// Prints one line per instant: the time and the values with 17 significant
// digits; exit status 1 and the reason on stderr when Simbody fails.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "Simbody.h"
#include "tests/spatial/spatial_mechanisms.h"
#include "tests/spatial/spatial_oracle.h"

namespace {

using namespace SimTK;

std::string g_integrator = "rkm";
bool g_energy = false;

Rotation Initial(const mbopt::oracle::SpatialDoublePendulum& p, int body) {
  return Rotation(p.angle_rad[body], UnitVec3(Vec3(p.axis[body][0], p.axis[body][1], p.axis[body][2])));
}

Body::Rigid Link(const mbopt::oracle::SpatialDoublePendulum& p, int body) {
  const double* j = p.inertia_kg_m2[body];
  return Body::Rigid(MassProperties(p.mass_kg[body], Vec3(0), Inertia(Vec3(j[0], j[1], j[2]))));
}

int DoublePendulum(bool spinning, double accuracy, const std::vector<double>& times) {
  const mbopt::oracle::SpatialDoublePendulum p;
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  Force::UniformGravity gravity(forces, matter, Vec3(0, 0, -p.g));
  MobilizedBody::Ball upper(matter.Ground(), Transform(), Link(p, 0), Transform(Vec3(0, 0, p.half_length_m[0])));
  MobilizedBody::Ball lower(upper, Transform(Vec3(0, 0, -p.half_length_m[0])), Link(p, 1),
                            Transform(Vec3(0, 0, p.half_length_m[1])));
  State state = system.realizeTopology();
  const Rotation r1 = Initial(p, 0), r2 = Initial(p, 1);
  upper.setQToFitRotation(state, r1);
  lower.setQToFitRotation(state, Rotation(~r1 * r2));
  const double* w = p.angular_velocity_rad_per_s;
  upper.setUToFitAngularVelocity(state, spinning ? Vec3(w[0], w[1], w[2]) : Vec3(0));
  lower.setUToFitAngularVelocity(state, Vec3(0));
  RungeKuttaMersonIntegrator integrator(system);
  integrator.setAccuracy(accuracy);
  TimeStepper stepper(system, integrator);
  stepper.initialize(state);
  for (double t : times) {
    if (t > 0.0) stepper.stepTo(t);
    const State& s = integrator.getState();
    system.realize(s, Stage::Position);
    std::printf("%.17g", t);
    for (const MobilizedBody* b : {static_cast<const MobilizedBody*>(&upper), static_cast<const MobilizedBody*>(&lower)}) {
      const Vec3 c = b->getBodyOriginLocation(s);
      std::printf(" %.17g %.17g %.17g", c[0], c[1], c[2]);
    }
    for (const MobilizedBody* b : {static_cast<const MobilizedBody*>(&upper), static_cast<const MobilizedBody*>(&lower)}) {
      const Rotation& r = b->getBodyRotation(s);
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) std::printf(" %.17g", r[i][k]);
      }
    }
    std::printf("\n");
  }
  return 0;
}


Vec3 V(const mbopt::oracle::Vec& v) { return Vec3(v[0], v[1], v[2]); }
Vec3 V3(const double* v) { return Vec3(v[0], v[1], v[2]); }

Rotation R(const mbopt::oracle::Mat& m) {
  return Rotation(Mat33(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]));
}

// Simulates a mechanism of spatial_mechanisms.h and prints its values;
// with cpu_repeats > 0 it integrates that many times and first prints the
// median CPU time of the stepping and the steps taken ("# CPU_S STEPS").
int ClosedLoop(const mbopt::oracle::Mechanism& m, double accuracy, const std::vector<double>& times,
               int cpu_repeats) {
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  Force::UniformGravity gravity(forces, matter, V(m.gravity_m_per_s2));
  std::vector<MobilizedBody> bodies(m.bodies.size());
  std::vector<bool> placed(m.bodies.size(), false);
  // A joint's frame W at its point, in body `b`'s axes (ground: world).
  auto frame_in = [&](int b, const mbopt::oracle::MechanismJoint& j) {
    const Transform world(R(j.axes), V(j.point_m));
    if (b < 0) return world;
    const Transform body(R(m.bodies[b].orientation), V(m.bodies[b].position_m));
    return Transform(~body * world);
  };
  auto mobod = [&](int b) -> MobilizedBody& { return b < 0 ? matter.updGround() : bodies[b]; };
  std::vector<const mbopt::oracle::MechanismJoint*> closures;
  // Each mobilizer's joint and its F frame's axes in world at the start.
  std::vector<std::pair<const mbopt::oracle::MechanismJoint*, Rotation>> mobilizers;
  // A Slider translates along its frames' common x axis: W turned to put x on W's z.
  const Rotation x_onto_z(-Pi / 2, YAxis);
  for (size_t k = 0; k < m.joints.size(); ++k) {
    const mbopt::oracle::MechanismJoint& j = m.joints[k];
    const bool parent_ready = j.a < 0 || placed[j.a];
    if (!parent_ready || j.b < 0 || placed[j.b]) {
      if (static_cast<int>(k) == m.driven_joint) throw std::runtime_error("a driven joint must be a mobilizer");
      closures.push_back(&j);
      continue;
    }
    const mbopt::oracle::MechanismBody& mb = m.bodies[j.b];
    const Body::Rigid info(MassProperties(mb.mass_kg, Vec3(0), Inertia(mb.principal_moments_kg_m2[0], mb.principal_moments_kg_m2[1], mb.principal_moments_kg_m2[2])));
    MobilizedBody& parent = mobod(j.a);
    const Transform x_pf = frame_in(j.a, j), x_bm = frame_in(j.b, j);
    mobilizers.emplace_back(&j, j.kind == mbopt::oracle::MechanismJointKind::kPrismatic ? R(j.axes) * x_onto_z
                                                                                        : R(j.axes));
    switch (j.kind) {
      case mbopt::oracle::MechanismJointKind::kRevolute:
        bodies[j.b] = MobilizedBody::Pin(parent, x_pf, info, x_bm);
        break;
      case mbopt::oracle::MechanismJointKind::kSpherical:
        bodies[j.b] = MobilizedBody::Ball(parent, x_pf, info, x_bm);
        break;
      case mbopt::oracle::MechanismJointKind::kUniversal:
        bodies[j.b] = MobilizedBody::Universal(parent, x_pf, info, x_bm);
        break;
      case mbopt::oracle::MechanismJointKind::kPrismatic:
        bodies[j.b] = MobilizedBody::Slider(parent, Transform(x_pf.R() * x_onto_z, x_pf.p()), info,
                                            Transform(x_bm.R() * x_onto_z, x_bm.p()));
        break;
      case mbopt::oracle::MechanismJointKind::kPointOnLine:
        throw std::runtime_error("a point-on-line joint must close a loop");
    }
    placed[j.b] = true;
    if (static_cast<int>(k) == m.driven_joint) Motion::Steady(bodies[j.b], m.driver_rate_rad_per_s);
  }
  for (const mbopt::oracle::MechanismJoint* j : closures) {
    MobilizedBody& a = mobod(j->a);
    MobilizedBody& b = mobod(j->b);
    const Transform fa = frame_in(j->a, *j), fb = frame_in(j->b, *j);
    switch (j->kind) {
      case mbopt::oracle::MechanismJointKind::kSpherical:
        Constraint::Ball(a, fa.p(), b, fb.p());
        break;
      case mbopt::oracle::MechanismJointKind::kRevolute:
        Constraint::Ball(a, fa.p(), b, fb.p());
        Constraint::ConstantAngle(a, fa.z(), b, fb.x(), Pi / 2);
        Constraint::ConstantAngle(a, fa.z(), b, fb.y(), Pi / 2);
        break;
      case mbopt::oracle::MechanismJointKind::kUniversal:
        Constraint::Ball(a, fa.p(), b, fb.p());
        Constraint::ConstantAngle(a, fa.x(), b, fb.y(), Pi / 2);
        break;
      case mbopt::oracle::MechanismJointKind::kPointOnLine:
        Constraint::PointOnLine(a, fa.z(), fa.p(), b, fb.p());
        break;
      case mbopt::oracle::MechanismJointKind::kPrismatic:
        throw std::runtime_error("a prismatic joint must be a mobilizer");
    }
  }
  State state = system.realizeTopology();
  // Every mobilizer at q = 0 is the initial pose; the driven one's rate and
  // the velocities the loops then need come from the projection below,
  // starting from the bodies' given velocities: each mobilizer's F and M
  // frames coincide at the start, so its relative velocity is that of the
  // child's point at the joint less the parent's, in F's axes.
  system.realize(state, Stage::Position);
  auto point_velocity = [&](int b, const Vec3& point) {
    if (b < 0) return Vec3(0);
    const mbopt::oracle::MechanismBody& mb = m.bodies[b];
    return V(mb.velocity_m_per_s) + V(mb.angular_velocity_rad_per_s) % (point - V(mb.position_m));
  };
  auto angular_velocity = [&](int b) { return b < 0 ? Vec3(0) : V(m.bodies[b].angular_velocity_rad_per_s); };
  for (const auto& [j, f_axes] : mobilizers) {
    const Vec3 w_fm = angular_velocity(j->b) - angular_velocity(j->a);
    const Vec3 v_fm = point_velocity(j->b, V(j->point_m)) - point_velocity(j->a, V(j->point_m));
    bodies[j->b].setUToFitVelocity(state, SpatialVec(~f_axes * w_fm, ~f_axes * v_fm));
  }
  system.project(state, 1e-14);
  // The constraint tolerance follows the accuracy (as tests/oracle's, a
  // hundredth of it) but not below 1e-12, where the comparisons run.
  const double constraint_tolerance = std::max(accuracy * 1e-2, 1e-12);
  std::vector<double> cpu_seconds;
  std::vector<std::vector<double>> values;
  long steps = 0;
  for (int repeat = 0; repeat < std::max(cpu_repeats, 1); ++repeat) {
    values.clear();
    const std::clock_t start = std::clock();
    std::unique_ptr<Integrator> integrator;
    if (g_integrator == "cpodes") {
      integrator = std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
    } else {
      integrator = std::make_unique<RungeKuttaMersonIntegrator>(system);
    }
    integrator->setAccuracy(accuracy);
    integrator->setConstraintTolerance(constraint_tolerance);
    TimeStepper stepper(system, *integrator);
    stepper.initialize(state);
    for (double t : times) {
      if (t > 0.0) stepper.stepTo(t);
      const State& s = integrator->getState();
      system.realize(s, Stage::Position);
      std::vector<double> row{t};
      for (const MobilizedBody& b : bodies) {
        const Vec3 c = b.getBodyOriginLocation(s);
        for (int k = 0; k < 3; ++k) row.push_back(c[k]);
        const Rotation& r = b.getBodyRotation(s);
        for (int i = 0; i < 3; ++i) {
          for (int k = 0; k < 3; ++k) row.push_back(r[i][k]);
        }
      }
      if (g_energy) {
        system.realize(s, Stage::Dynamics);
        row.push_back(system.calcEnergy(s));
      }
      values.push_back(row);
    }
    cpu_seconds.push_back(static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC);
    steps = integrator->getNumStepsTaken();
  }
  if (cpu_repeats > 0) {
    std::sort(cpu_seconds.begin(), cpu_seconds.end());
    std::printf("# %.9g %ld\n", cpu_seconds[cpu_seconds.size() / 2], steps);
  }
  for (const std::vector<double>& row : values) {
    for (size_t k = 0; k < row.size(); ++k) std::printf(k == 0 ? "%.17g" : " %.17g", row[k]);
    std::printf("\n");
  }
  return 0;
}

// Released at rest straight down and brought to rest by the hinges'
// dampers: at END_S the state is the static equilibrium.
int HungChain(double accuracy, const std::vector<double>& times) {
  const mbopt::oracle::SpatialHungChain p;
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  Force::UniformGravity gravity(forces, matter, Vec3(0, 0, -p.g));
  auto link = [&](int i) {
    const double* j = p.inertia_kg_m2[i];
    return Body::Rigid(MassProperties(p.mass_kg[i], Vec3(0), Inertia(Vec3(j[0], j[1], j[2]))));
  };
  // A pin turns about its frames' z axes: world x for the upper hinge, world y for the lower.
  const Rotation about_x(Pi / 2, YAxis), about_y(-Pi / 2, XAxis);
  MobilizedBody::Pin upper(matter.Ground(), Transform(about_x, Vec3(0)), link(0),
                           Transform(about_x, Vec3(0, 0, p.half_length_m[0])));
  MobilizedBody::Pin lower(upper, Transform(about_y, Vec3(0, 0, -p.half_length_m[0])), link(1),
                           Transform(about_y, Vec3(0, 0, p.half_length_m[1])));
  const MobilizedBody* bodies[2] = {&upper, &lower};
  for (int i = 0; i < 2; ++i) {
    Force::TwoPointLinearSpring(forces, matter.Ground(), Vec3(p.anchor_m[i][0], p.anchor_m[i][1], p.anchor_m[i][2]),
                                *bodies[i], Vec3(p.attachment_m[i][0], p.attachment_m[i][1], p.attachment_m[i][2]),
                                p.stiffness_n_per_m[i], p.free_length_m[i]);
    Force::MobilityLinearDamper(forces, *bodies[i], MobilizerUIndex(0), p.hinge_damping_n_m_s_per_rad[i]);
  }
  State state = system.realizeTopology();
  RungeKuttaMersonIntegrator integrator(system);
  integrator.setAccuracy(accuracy);
  TimeStepper stepper(system, integrator);
  stepper.initialize(state);
  for (double t : times) {
    if (t > 0.0) stepper.stepTo(t);
    const State& s = integrator.getState();
    system.realize(s, Stage::Position);
    std::printf("%.17g", t);
    for (const MobilizedBody* b : bodies) {
      const Vec3 c = b->getBodyOriginLocation(s);
      std::printf(" %.17g %.17g %.17g", c[0], c[1], c[2]);
    }
    for (const MobilizedBody* b : bodies) {
      const Rotation& r = b->getBodyRotation(s);
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) std::printf(" %.17g", r[i][k]);
      }
    }
    std::printf("\n");
  }
  return 0;
}

// The body of SpatialBushingBody on a Free mobilizer (its frame at the
// centre of mass), held by Force::LinearBushing.
int BushingBody(double accuracy, const std::vector<double>& times) {
  const mbopt::oracle::SpatialBushingBody p;
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  Force::UniformGravity gravity(forces, matter, Vec3(0, 0, -p.g));
  const Body::Rigid info(
      MassProperties(p.mass_kg, Vec3(0), Inertia(Vec3(p.inertia_kg_m2[0], p.inertia_kg_m2[1], p.inertia_kg_m2[2]))));
  MobilizedBody::Free body(matter.Ground(), Transform(), info, Transform());
  const Rotation ground_axes(p.ground_angle_rad, UnitVec3(V3(p.ground_axis)));
  const Vec3 ground_origin = V3(p.ground_frame_m), body_frame = V3(p.body_frame_m);
  Vec6 stiffness, damping;
  for (int k = 0; k < 6; ++k) {
    stiffness[k] = p.stiffness[k];
    damping[k] = p.damping[k];
  }
  Force::LinearBushing bushing(forces, matter.Ground(), Transform(ground_axes, ground_origin), body,
                               Transform(Rotation(), body_frame), stiffness, damping);
  State state = system.realizeTopology();
  const Rotation turned = ground_axes * Rotation(p.turn_angle_rad, UnitVec3(V3(p.turn_axis)));
  const Vec3 origin = ground_origin + ground_axes * V3(p.displacement_m) - turned * body_frame;
  body.setQToFitTransform(state, Transform(turned, origin));
  body.setUToFitAngularVelocity(state, V3(p.angular_velocity_rad_per_s));
  body.setUToFitLinearVelocity(state, V3(p.velocity_m_per_s));
  RungeKuttaMersonIntegrator integrator(system);
  integrator.setAccuracy(accuracy);
  TimeStepper stepper(system, integrator);
  stepper.initialize(state);
  for (double t : times) {
    if (t > 0.0) stepper.stepTo(t);
    const State& s = integrator.getState();
    system.realize(s, Stage::Position);
    std::printf("%.17g", t);
    const Vec3 c = body.getBodyOriginLocation(s);
    std::printf(" %.17g %.17g %.17g", c[0], c[1], c[2]);
    const Rotation& r = body.getBodyRotation(s);
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) std::printf(" %.17g", r[i][k]);
    }
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int cpu_repeats = 0;
  int first = 1;
  for (; first < argc && std::string(argv[first]).rfind("--", 0) == 0; ++first) {
    const std::string option = argv[first];
    if (option == "--integrator=rkm" || option == "--integrator=cpodes") {
      g_integrator = option.substr(13);
    } else if (option.rfind("--cpu=", 0) == 0 && std::atoi(option.c_str() + 6) > 0) {
      cpu_repeats = std::atoi(option.c_str() + 6);
    } else if (option == "--energy") {
      g_energy = true;
    } else {
      std::fprintf(stderr,
                   "unknown option '%s' (expected --integrator=rkm|cpodes, --cpu=REPEATS > 0 or --energy)\n",
                   option.c_str());
      return 2;
    }
  }
  if (argc - first != 4) {
    std::fprintf(stderr,
                 "usage: %s [--integrator=rkm|cpodes] [--cpu=REPEATS] [--energy] MECHANISM ACCURACY END_S INTERVALS\n",
                 argv[0]);
    return 2;
  }
  const std::string mechanism = argv[first];
  const double accuracy = std::atof(argv[first + 1]), end_s = std::atof(argv[first + 2]);
  const int intervals = std::atoi(argv[first + 3]);
  std::vector<double> times;
  for (int i = 0; i <= intervals; ++i) times.push_back(end_s * i / intervals);
  try {
    if (mechanism == "double_pendulum") return DoublePendulum(false, accuracy, times);
    if (mechanism == "spinning_double_pendulum") return DoublePendulum(true, accuracy, times);
    if (mechanism == "hung_chain") return HungChain(accuracy, times);
    if (mechanism == "bushing_body") return BushingBody(accuracy, times);
    if (mechanism == "bricard") return ClosedLoop(mbopt::oracle::Bricard(), accuracy, times, cpu_repeats);
    if (mechanism == "rssr") return ClosedLoop(mbopt::oracle::Rssr(), accuracy, times, cpu_repeats);
    if (mechanism == "cardan") return ClosedLoop(mbopt::oracle::CardanShaft(), accuracy, times, cpu_repeats);
    if (mechanism == "slider_crank") {
      return ClosedLoop(mbopt::oracle::SpatialSliderCrank(), accuracy, times, cpu_repeats);
    }
    if (mechanism == "spherical_chain") {
      return ClosedLoop(mbopt::oracle::SphericalChain(), accuracy, times, cpu_repeats);
    }
    std::fprintf(stderr, "unknown mechanism '%s'\n", mechanism.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "Simbody failed: %s\n", e.what());
    return 1;
  }
}
