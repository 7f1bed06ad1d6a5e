// Drawings of scenes (spec::SceneDrawing) as inline SVG, animated over the
// time grid: bodies as rounded outlines around their points, pins as
// circles, sliders as blocks on their axis, pins in slots, springs as
// zigzags, dampers as pots, ground hatched, inputs as arrows, flexible links
// as their centre lines. x and y share one scale (a circle stays round);
// +y is up.
//
// Each drawn instant is one <g class="frame"> of the <svg>, all but the
// first hidden; a range slider and a play button under it show one at a
// time through a few lines of inline JavaScript, with the time beside them.
// Nothing is fetched: no external file, font, script or link.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spec/scene_drawing.h"

namespace mbopt::report {

// One drawing of a figure; several are overlaid on the same axes and
// animated by one slider (the initial and final designs of a report share
// the time grid; a drawing with fewer instants holds its last one).
struct DrawingLayer {
  const spec::SceneDrawing* drawing = nullptr;
  std::string label;         // legend, e.g. "initial design"
  std::string color = "#1f4e9a";  // outlines and symbols (CSS colour)
  std::string fill = "#c9d8f0";   // the bodies' fill
  double opacity = 1.0;
};

// At most this many instants become frames (evenly picked, first and last
// kept): a page stays a few hundred kilobytes whatever the grid.
inline constexpr int kMaxDrawingFrames = 240;

// The instants of a grid of `instants` drawn as frames: all, or
// kMaxDrawingFrames picked evenly.
std::vector<size_t> FrameInstants(size_t instants);

// The figure (<div> with the <svg>, the controls and its script); `id`
// makes its elements' ids unique on a page (letters, digits, '-'). An
// animated figure's element has a function showTime(t), which shows the
// frame nearest t (s): a page's other controls move it. The axes hold
// every instant of the layers and of `extent`, drawings not drawn here
// (the other load cases' on a page), so figures given each other's
// drawings share one scale and window.
std::string MechanismFigureHtml(const std::vector<DrawingLayer>& layers, const std::string& id,
                                const std::vector<const spec::SceneDrawing*>& extent = {});

// One load case of a study (spec::LoadCase): the scene with the parameters
// the case sets, at both designs; `note` says why one is missing.
struct LoadCaseDrawings {
  std::string name;
  std::optional<spec::SceneDrawing> initial, final;
  std::string note;
};

// The report's "Mechanism" section: the job's scene drawn at the initial
// and at the final design, overlaid and animated together. Either may be
// missing; `note` then says why (the scene kind has no drawing, the worker
// program was not found, not asked for).
struct MechanismDrawings {
  std::optional<spec::SceneDrawing> initial, final;
  std::string note;
  // A study with load cases: one figure per case, in the study's order,
  // headed by its name (`initial` and `final` are then not drawn;
  // client/report/load_case_drawings.h draws them).
  std::vector<LoadCaseDrawings> cases;
};
// Empty when there is neither a drawing nor a note.
std::string MechanismSectionHtml(const MechanismDrawings& mechanism);

// A whole self-contained HTML page with the figure of one drawing: what
// `mbopt draw` writes.
std::string SceneDrawingPageHtml(const spec::SceneDrawing& drawing, const std::string& source);

}  // namespace mbopt::report
