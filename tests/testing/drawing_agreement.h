// How closely two drawings of one scene agree frame by frame, for tests
// that draw a scene two ways (the default integration path and the
// explicit one) and hold the frames to each other.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "spec/scene_drawing.h"

namespace mbopt::testing {

struct DrawingAgreement {
  bool same_frames = false;     // the same instants, points and points per frame
  double largest_gap_m = 0.0;   // a point's largest coordinate difference at an instant
  std::string largest_gap_at;   // which point, when
  double largest_travel_m = 0.0;  // how far a point of `b` gets from its place in b's first frame
  bool bitwise_same = true;     // every coordinate of every frame equal to the bit
};

inline DrawingAgreement CompareFrames(const spec::SceneDrawing& a, const spec::SceneDrawing& b) {
  DrawingAgreement agreement;
  agreement.same_frames = !a.times_s.empty() && a.times_s == b.times_s && a.point_names == b.point_names &&
                          a.points_m.size() == a.times_s.size() && b.points_m.size() == a.times_s.size();
  for (std::size_t i = 0; agreement.same_frames && i < a.times_s.size(); ++i) {
    agreement.same_frames = a.points_m[i].size() == a.point_names.size() && b.points_m[i].size() == a.point_names.size();
  }
  if (!agreement.same_frames) return agreement;
  for (std::size_t i = 0; i < a.times_s.size(); ++i) {
    for (std::size_t k = 0; k < a.point_names.size(); ++k) {
      const spec::DrawingPosition &p = a.points_m[i][k], &q = b.points_m[i][k], &start = b.points_m[0][k];
      const double gap = std::max({std::abs(p.x_m - q.x_m), std::abs(p.y_m - q.y_m), std::abs(p.z_m - q.z_m)});
      if (gap > agreement.largest_gap_m || std::isnan(gap)) {
        agreement.largest_gap_m = std::isnan(gap) ? HUGE_VAL : gap;
        agreement.largest_gap_at = a.point_names[k] + " at t = " + std::to_string(a.times_s[i]) + " s";
      }
      agreement.largest_travel_m =
          std::max(agreement.largest_travel_m, std::hypot(q.x_m - start.x_m, q.y_m - start.y_m, q.z_m - start.z_m));
      agreement.bitwise_same = agreement.bitwise_same && p.x_m == q.x_m && p.y_m == q.y_m && p.z_m == q.z_m;
    }
  }
  return agreement;
}

// What a scene drawn on the explicit path must share with its drawing on
// the default path (IDAS): the same instants and points, every point within
// `tolerance_m` of IDAS's at every instant; a point moving more than
// `least_travel_m` (a drawing repeating its start fails) and some
// coordinate not IDAS's to the bit (the explicit path ran).
inline void ExpectTheFramesOfTheDefaultPath(const spec::SceneDrawing& idas, const spec::SceneDrawing& explicit_path,
                                            double tolerance_m, double least_travel_m, const std::string& scene) {
  const DrawingAgreement agreement = CompareFrames(idas, explicit_path);
  ASSERT_TRUE(agreement.same_frames) << scene << ": the explicit drawing's instants or points are not IDAS's";
  EXPECT_LT(agreement.largest_gap_m, tolerance_m) << scene << ": " << agreement.largest_gap_at;
  EXPECT_GT(agreement.largest_travel_m, least_travel_m) << scene;
  EXPECT_FALSE(agreement.bitwise_same) << scene << ": the explicit drawing is IDAS's to the bit: was the path taken?";
  std::cout << scene << " drawn on both paths: positions differ by " << agreement.largest_gap_m
            << " m at most, largest travel " << agreement.largest_travel_m << " m\n";
}

}  // namespace mbopt::testing
