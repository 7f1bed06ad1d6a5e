// Simbody simulating the mechanisms of spatial_oracle.h, as a program of
// its own for the reasons tests/oracle/simbody_oracle.h gives (Simbody 3.7's
// headers are C++17 and its SimTKmath exports an old SUNDIALS' symbols).
//
//   mbopt_simbody_spatial_oracle MECHANISM ACCURACY END_S INTERVALS
//
// MECHANISM is double_pendulum (released at rest) or
// spinning_double_pendulum (spatial_oracle.h).
//
// Prints one line per instant: the time and the values with 17 significant
// digits; exit status 1 and the reason on stderr when Simbody fails.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "Simbody.h"
#include "tests/spatial/spatial_oracle.h"

namespace {

using namespace SimTK;

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

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s MECHANISM ACCURACY END_S INTERVALS\n", argv[0]);
    return 2;
  }
  const std::string mechanism = argv[1];
  const double accuracy = std::atof(argv[2]), end_s = std::atof(argv[3]);
  const int intervals = std::atoi(argv[4]);
  std::vector<double> times;
  for (int i = 0; i <= intervals; ++i) times.push_back(end_s * i / intervals);
  try {
    if (mechanism == "double_pendulum") return DoublePendulum(false, accuracy, times);
    if (mechanism == "spinning_double_pendulum") return DoublePendulum(true, accuracy, times);
    std::fprintf(stderr, "unknown mechanism '%s'\n", mechanism.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "Simbody failed: %s\n", e.what());
    return 1;
  }
}
