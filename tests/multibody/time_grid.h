// The output instants the engine's dynamics tests ask for.
#pragma once

#include <vector>

namespace mbopt::multibody::testing {

// `intervals` + 1 evenly spaced instants from 0 to end_s.
inline std::vector<double> Grid(double end_s, int intervals) {
  std::vector<double> t;
  for (int i = 0; i <= intervals; ++i) t.push_back(end_s * i / intervals);
  return t;
}

}  // namespace mbopt::multibody::testing
