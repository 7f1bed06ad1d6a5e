// The unit table: the units a scene or study may write its numbers in, each
// with its factor to SI and its physical dimension. Conversion happens once,
// where data enters (spec/io); everything past that point is SI.
//
// Unit strings are matched exactly (after trimming spaces at the ends), e.g.
// "lbf/in", "lbf s^2/in", "kg m^2". The empty string means SI (or
// dimensionless) and converts with factor 1 to any dimension.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::spec {

enum class Dimension {
  kAny,  // "": SI of whatever the quantity is
  kLength,
  kMass,
  kTime,
  kAngle,
  kForce,
  kStiffness,  // force / length
  kDamping,    // force * time / length
  kInertia,    // mass * length^2
  kPressure,   // also stress
  kArea,
  kDensity,  // mass / length^3
  kVelocity,
  kAcceleration,
  kAngularVelocity,
  kTorque,
  kEnergy,               // J; the same SI units as torque, but not a torque
  kPower,
  kRotationalStiffness,  // torque / angle
  kRotationalDamping,    // torque * time / angle
};

const char* DimensionName(Dimension d);

// The SI unit of a dimension as the unit table writes it ("N/m", "J"); ""
// for kAny (dimensionless, or not known).
const char* SiUnitName(Dimension d);

struct Unit {
  std::string name;
  double si_per_unit = 1.0;  // value_si = value_in_unit * si_per_unit
  Dimension dimension = Dimension::kAny;
};

// NotFound (listing the known units) if `name` is not in the table.
absl::StatusOr<Unit> FindUnit(const std::string& name);

// Every unit of the table, in table order (for documentation and messages).
const std::vector<Unit>& AllUnits();

// True if a value in `unit` may stand for a quantity of `dimension`.
bool UnitFits(const Unit& unit, Dimension dimension);

}  // namespace mbopt::spec
