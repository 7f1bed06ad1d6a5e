#include "spec/units.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"

namespace mbopt::spec {
namespace {

// Exact definitions: the inch is 0.0254 m and the pound-force is
// 4.4482216152605 N (international avoirdupois pound times standard gravity).
constexpr double kInch = 0.0254;
constexpr double kPoundForce = 4.4482216152605;
constexpr double kPi = 3.14159265358979323846;

std::vector<Unit> MakeTable() {
  using D = Dimension;
  return {
      {"", 1.0, D::kAny},
      {"m", 1.0, D::kLength},
      {"mm", 1e-3, D::kLength},
      {"cm", 1e-2, D::kLength},
      {"in", kInch, D::kLength},
      {"ft", 12 * kInch, D::kLength},
      {"kg", 1.0, D::kMass},
      {"g", 1e-3, D::kMass},
      {"lbf s^2/in", kPoundForce / kInch, D::kMass},
      {"s", 1.0, D::kTime},
      {"ms", 1e-3, D::kTime},
      {"rad", 1.0, D::kAngle},
      {"deg", kPi / 180.0, D::kAngle},
      {"N", 1.0, D::kForce},
      {"kN", 1e3, D::kForce},
      {"lbf", kPoundForce, D::kForce},
      {"N/m", 1.0, D::kStiffness},
      {"N/mm", 1e3, D::kStiffness},
      {"kN/m", 1e3, D::kStiffness},
      {"lbf/in", kPoundForce / kInch, D::kStiffness},
      {"N s/m", 1.0, D::kDamping},
      {"kN s/m", 1e3, D::kDamping},
      {"N s/mm", 1e3, D::kDamping},
      {"lbf s/in", kPoundForce / kInch, D::kDamping},
      {"kg m^2", 1.0, D::kInertia},
      {"lbf in s^2", kPoundForce * kInch, D::kInertia},
      {"Pa", 1.0, D::kPressure},
      {"kPa", 1e3, D::kPressure},
      {"MPa", 1e6, D::kPressure},
      {"GPa", 1e9, D::kPressure},
      {"psi", kPoundForce / (kInch * kInch), D::kPressure},
      {"m^2", 1.0, D::kArea},
      {"mm^2", 1e-6, D::kArea},
      {"cm^2", 1e-4, D::kArea},
      {"in^2", kInch * kInch, D::kArea},
      {"kg/m^3", 1.0, D::kDensity},
      {"m/s", 1.0, D::kVelocity},
      {"mm/s", 1e-3, D::kVelocity},
      {"in/s", kInch, D::kVelocity},
      {"km/h", 1.0 / 3.6, D::kVelocity},
      {"m/s^2", 1.0, D::kAcceleration},
      {"mm/s^2", 1e-3, D::kAcceleration},
      {"in/s^2", kInch, D::kAcceleration},
      {"rad/s", 1.0, D::kAngularVelocity},
      {"deg/s", kPi / 180.0, D::kAngularVelocity},
      {"rpm", 2 * kPi / 60.0, D::kAngularVelocity},
      {"N m", 1.0, D::kTorque},
      {"N mm", 1e-3, D::kTorque},
      {"kN m", 1e3, D::kTorque},
      {"lbf in", kPoundForce * kInch, D::kTorque},
      {"J", 1.0, D::kEnergy},
      {"kJ", 1e3, D::kEnergy},
      {"mJ", 1e-3, D::kEnergy},
      {"W", 1.0, D::kPower},
      {"kW", 1e3, D::kPower},
      {"N m/rad", 1.0, D::kRotationalStiffness},
      {"N m/deg", 180.0 / kPi, D::kRotationalStiffness},
      {"N m s/rad", 1.0, D::kRotationalDamping},
  };
}

}  // namespace

const std::vector<Unit>& AllUnits() {
  static const std::vector<Unit>* const table = new std::vector<Unit>(MakeTable());
  return *table;
}

const char* DimensionName(Dimension d) {
  switch (d) {
    case Dimension::kAny:
      return "any (SI)";
    case Dimension::kLength:
      return "length";
    case Dimension::kMass:
      return "mass";
    case Dimension::kTime:
      return "time";
    case Dimension::kAngle:
      return "angle";
    case Dimension::kForce:
      return "force";
    case Dimension::kStiffness:
      return "stiffness (force/length)";
    case Dimension::kDamping:
      return "damping (force time/length)";
    case Dimension::kInertia:
      return "rotary inertia (mass length^2)";
    case Dimension::kPressure:
      return "pressure/stress";
    case Dimension::kArea:
      return "area";
    case Dimension::kDensity:
      return "density";
    case Dimension::kVelocity:
      return "velocity";
    case Dimension::kAcceleration:
      return "acceleration";
    case Dimension::kAngularVelocity:
      return "angular velocity";
    case Dimension::kTorque:
      return "torque";
    case Dimension::kEnergy:
      return "energy";
    case Dimension::kPower:
      return "power";
    case Dimension::kRotationalStiffness:
      return "rotational stiffness (torque/angle)";
    case Dimension::kRotationalDamping:
      return "rotational damping (torque time/angle)";
  }
  return "unknown";
}

const char* SiUnitName(Dimension d) {
  switch (d) {
    case Dimension::kAny: return "";
    case Dimension::kLength: return "m";
    case Dimension::kMass: return "kg";
    case Dimension::kTime: return "s";
    case Dimension::kAngle: return "rad";
    case Dimension::kForce: return "N";
    case Dimension::kStiffness: return "N/m";
    case Dimension::kDamping: return "N s/m";
    case Dimension::kInertia: return "kg m^2";
    case Dimension::kPressure: return "Pa";
    case Dimension::kArea: return "m^2";
    case Dimension::kDensity: return "kg/m^3";
    case Dimension::kVelocity: return "m/s";
    case Dimension::kAcceleration: return "m/s^2";
    case Dimension::kAngularVelocity: return "rad/s";
    case Dimension::kTorque: return "N m";
    case Dimension::kEnergy: return "J";
    case Dimension::kPower: return "W";
    case Dimension::kRotationalStiffness: return "N m/rad";
    case Dimension::kRotationalDamping: return "N m s/rad";
  }
  return "";
}

absl::StatusOr<Unit> FindUnit(const std::string& name) {
  const std::string trimmed(absl::StripAsciiWhitespace(name));
  for (const Unit& unit : AllUnits()) {
    if (unit.name == trimmed) return unit;
  }
  std::vector<std::string> names;
  for (const Unit& unit : AllUnits()) {
    if (!unit.name.empty()) names.push_back(absl::StrCat("\"", unit.name, "\""));
  }
  return absl::NotFoundError(absl::StrCat(
      "unknown unit \"", trimmed, "\"; known units: \"\" (SI), ", absl::StrJoin(names, ", ")));
}

bool UnitFits(const Unit& unit, Dimension dimension) {
  return unit.dimension == Dimension::kAny || dimension == Dimension::kAny ||
         unit.dimension == dimension;
}

}  // namespace mbopt::spec
