// A self-contained SVG scatter plot of wall time against objective error
// (both on log axes), with the Pareto front (no other point is both faster
// and more accurate) joined and marked. No scripts, no external fonts.
#pragma once

#include <string>
#include <vector>

namespace mbopt::accuracy {

struct PlotPoint {
  std::string label;
  double wall_seconds = 0;
  double error = 0;        // relative; values below the plot's floor sit on it
  bool is_default = false;
  bool violated = false;   // the re-checked design violates a constraint
};

// Indices of the Pareto-optimal points (minimize both wall time and error),
// ordered by wall time.
std::vector<int> ParetoFront(const std::vector<PlotPoint>& points);

std::string ParetoSvg(const std::string& title, const std::vector<PlotPoint>& points,
                      double error_floor);

}  // namespace mbopt::accuracy
