#include "server/slp/finite_difference.h"

#include <algorithm>
#include <cmath>

namespace mbopt::slp {

double NominalStep(double x, double lower, double upper, const SlpOptions& o) {
  const double typical = o.move_limit_floor_fraction_of_range * (upper - lower);
  return o.finite_difference_relative_step * std::max(std::abs(x), typical);
}

std::vector<double> PlanSteps(double x, double lower, double upper, const SlpOptions& o) {
  const double h = NominalStep(x, lower, upper, o);
  const double room_up = upper - x;
  const double room_down = x - lower;
  if (o.finite_difference == FiniteDifferenceScheme::kCentral) {
    const double hc = std::min({h, room_up, room_down});
    if (hc >= 0.5 * h) return {hc, -hc};
  }
  // One side: forward when it fits, else backward, else the side with room.
  if (h <= room_up) return {h};
  if (h <= room_down) return {-h};
  return room_up >= room_down ? std::vector<double>{room_up} : std::vector<double>{-room_down};
}

double RetryStep(double x, double lower, double upper, double failed_step) {
  const double opposite = -failed_step;
  const double target = x + opposite;
  if (target >= lower && target <= upper) return opposite;
  return 0.5 * failed_step;
}

std::optional<Eigen::VectorXd> DerivativeFromSamples(const Eigen::VectorXd& values_x0,
                                                     const std::vector<Sample>& samples) {
  const Sample* plus = nullptr;
  const Sample* minus = nullptr;
  for (const Sample& s : samples) {
    if (s.step > 0 && (plus == nullptr || s.step > plus->step)) plus = &s;
    if (s.step < 0 && (minus == nullptr || s.step < minus->step)) minus = &s;
  }
  if (plus != nullptr && minus != nullptr) {
    return Eigen::VectorXd((plus->values - minus->values) / (plus->step - minus->step));
  }
  const Sample* one = plus != nullptr ? plus : minus;
  if (one == nullptr) return std::nullopt;
  return Eigen::VectorXd((one->values - values_x0) / one->step);
}

}  // namespace mbopt::slp
