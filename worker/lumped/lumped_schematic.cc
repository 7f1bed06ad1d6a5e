#include "worker/lumped/lumped_schematic.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>

namespace mbopt::lumped {
namespace {

using Kind = spec::Attachment::Kind;

// Along y an element's end a sits above its end b; along x, to the right.
bool AlongY(const spec::SpringDamper& e) { return std::abs(e.direction_y) >= std::abs(e.direction_x); }

}  // namespace

spec::SceneDrawing LumpedSchematic(const spec::Scene& scene, const std::vector<double>& p) {
  spec::SceneDrawing d;
  d.scene_name = scene.name;
  d.schematic = true;
  const auto* m = std::get_if<spec::LumpedModel>(&scene.model);
  if (m == nullptr) {
    d.failure = "expected a lumped scene";
    return d;
  }
  const size_t n = m->bodies.size();
  // Levels: every body at least one above the ground; a body at end a of an
  // element along y one above the body at its end b. Longest paths in a
  // graph of n bodies need at most n rounds; a cycle (a mistake the
  // analysis does not mind) stops growing there.
  std::vector<int> level(n, 1);
  for (size_t round = 0; round < n; ++round) {
    for (const spec::SpringDamper& e : m->elements) {
      if (!AlongY(e) || e.a.kind != Kind::kBody || e.b.kind != Kind::kBody) continue;
      const bool up = e.direction_y >= 0.0;
      const int above = up ? e.a.index : e.b.index, below = up ? e.b.index : e.a.index;
      if (above < 0 || below < 0 || above >= static_cast<int>(n) || below >= static_cast<int>(n)) continue;
      level[static_cast<size_t>(above)] =
          std::max(level[static_cast<size_t>(above)], level[static_cast<size_t>(below)] + 1);
    }
  }
  double x_min = 0.0, x_max = 0.0;
  std::vector<double> x(n), y0(n);
  for (size_t b = 0; b < n; ++b) {
    x[b] = m->bodies[b].position_m.x.Resolve(p);
    y0[b] = m->bodies[b].position_m.y.Resolve(p);
    x_min = std::min(x_min, x[b]);
    x_max = std::max(x_max, x[b]);
  }
  for (const spec::SpringDamper& e : m->elements) {
    for (const spec::Attachment* at : {&e.a, &e.b}) {
      if (at->kind != Kind::kBody) continue;
      const double ax = x[static_cast<size_t>(at->index)] + at->offset_m.x.Resolve(p);
      x_min = std::min(x_min, ax);
      x_max = std::max(x_max, ax);
    }
  }
  // The spacing between levels follows the scene's width, so the drawing
  // keeps its proportions whatever the unit of the lengths.
  const double spacing = std::max(0.3 * (x_max - x_min), 0.2);
  const double box_height = 0.3 * spacing;
  std::vector<double> y(n);
  for (size_t b = 0; b < n; ++b) y[b] = y0[b] + level[b] * spacing;

  d.times_s = {0.0};
  std::vector<spec::DrawingPosition>& at = d.points_m.emplace_back();
  auto add = [&](const std::string& name, double px, double py) {
    at.push_back(spec::DrawingPosition{px, py});
    return d.AddPoint(name);
  };
  // A body's box spans its attachments (a chassis carrying several
  // suspensions is as long as their spread).
  for (size_t b = 0; b < n; ++b) {
    double left = x[b] - 0.4 * box_height, right = x[b] + 0.4 * box_height;
    for (const spec::SpringDamper& e : m->elements) {
      for (const spec::Attachment* a : {&e.a, &e.b}) {
        if (a->kind != Kind::kBody || a->index != static_cast<int>(b)) continue;
        const double ax = x[b] + a->offset_m.x.Resolve(p);
        left = std::min(left, ax - 0.4 * box_height);
        right = std::max(right, ax + 0.4 * box_height);
      }
    }
    const std::string& name = m->bodies[b].name;
    spec::SceneDrawing::Body body;
    body.name = name;
    body.points = {
        add(name + " corner", left, y[b] - box_height / 2), add(name + " corner", right, y[b] - box_height / 2),
        add(name + " corner", right, y[b] + box_height / 2), add(name + " corner", left, y[b] + box_height / 2)};
    d.bodies.push_back(std::move(body));
  }
  for (const spec::SpringDamper& e : m->elements) {
    // The body ends first: a ground or input end goes below (or beside) the
    // other end.
    const bool along_y = AlongY(e);
    const double sign = along_y ? (e.direction_y >= 0.0 ? 1.0 : -1.0) : (e.direction_x >= 0.0 ? 1.0 : -1.0);
    double ends[2][2] = {{0, 0}, {0, 0}};
    bool placed[2] = {false, false};
    const spec::Attachment* attachments[2] = {&e.a, &e.b};
    for (int k = 0; k < 2; ++k) {
      const spec::Attachment* a = attachments[k];
      if (a->kind != Kind::kBody || a->index < 0 || a->index >= static_cast<int>(n)) continue;
      const size_t b = static_cast<size_t>(a->index);
      // End a faces down (or left) towards end b, end b faces up.
      const double face = (k == 0 ? -1.0 : 1.0) * sign;
      ends[k][0] = x[b] + a->offset_m.x.Resolve(p) + (along_y ? 0.0 : face * 0.4 * box_height);
      ends[k][1] = y[b] + (along_y ? face * box_height / 2 : 0.0);
      placed[k] = true;
    }
    for (int k = 0; k < 2; ++k) {
      if (placed[k]) continue;
      const int other = 1 - k;
      const double face = (k == 0 ? 1.0 : -1.0) * sign;
      const double ox = placed[other] ? ends[other][0] : 0.0, oy = placed[other] ? ends[other][1] : 0.0;
      // The ground sits on level 0; beside the body for an element along x.
      ends[k][0] = along_y ? ox : ox + face * 0.6 * spacing;
      ends[k][1] = along_y ? 0.0 : oy;
    }
    spec::SceneDrawing::Element element;
    element.name = e.name;
    element.a = add(e.name + ".a", ends[0][0], ends[0][1]);
    element.b = add(e.name + ".b", ends[1][0], ends[1][1]);
    element.spring = e.stiffness_n_per_m.Resolve(p) != 0.0;
    element.damper = e.damping_n_s_per_m.Resolve(p) != 0.0;
    for (int k = 0; k < 2; ++k) {
      const int point = k == 0 ? element.a : element.b;
      const spec::Attachment* a = attachments[k];
      if (a->kind == Kind::kGround) d.ground_points.push_back(point);
      if (a->kind == Kind::kInput && a->index >= 0 && a->index < static_cast<int>(m->inputs.size())) {
        const spec::GroundInput& input = m->inputs[static_cast<size_t>(a->index)];
        d.inputs.push_back(spec::SceneDrawing::Input{input.name, point, input.direction_x, input.direction_y});
      }
    }
    d.elements.push_back(std::move(element));
  }
  return d;
}

}  // namespace mbopt::lumped
