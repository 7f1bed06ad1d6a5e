#include "client/report/load_case_drawings.h"

#include <optional>

#include "client/report/html_escape.h"

namespace mbopt::report {
namespace {

using spec::SceneDrawing;

// What a figure shows: a motion, or a lumped scene's layout.
std::string GridNote(const SceneDrawing& drawing) {
  return drawing.schematic ? std::string("a schematic (a lumped scene: its layout, not a motion)")
                           : std::to_string(drawing.times_s.size()) + " instants of the time grid";
}

}  // namespace

std::string LoadCaseSectionHtml(const MechanismDrawings& mechanism) {
  std::string out = "<h2>Mechanism</h2>\n";
  bool intro = false;
  for (size_t k = 0; k < mechanism.cases.size(); ++k) {
    const LoadCaseDrawings& c = mechanism.cases[k];
    const std::optional<SceneDrawing>& first = c.initial ? c.initial : c.final;
    if (first && !intro) {
      out += "<p class=\"note\">The scene once per load case, with the parameters the case sets, " +
             std::string(first->schematic ? "as a schematic (a lumped scene: its layout, not a motion)"
                                          : "over its time grid (the slider or the play button moves it)") +
             ", at the initial design (grey) and at the final design (blue), overlaid on the same axes.</p>\n";
      intro = true;
    }
    out += "<h3>Load case " + EscapeHtml(c.name) + "</h3>\n";
    std::vector<DrawingLayer> layers;
    if (c.initial) layers.push_back(DrawingLayer{&*c.initial, "initial design, " + c.name, "#7a7a7a", "#e6e6e6", 0.75});
    if (c.final) layers.push_back(DrawingLayer{&*c.final, "final design, " + c.name, "#1f4e9a", "#c9d8f0", 1.0});
    // Ids unique on the page: one figure per case.
    if (!layers.empty()) out += MechanismFigureHtml(layers, "mechanism-case-" + std::to_string(k));
    if (!c.note.empty()) out += "<p class=\"note\">" + EscapeHtml(c.note) + "</p>\n";
  }
  if (!mechanism.note.empty()) out += "<p class=\"note\">" + EscapeHtml(mechanism.note) + "</p>\n";
  return out;
}

std::string LoadCaseDrawingsPageHtml(const std::vector<CaseDrawing>& cases, const std::string& study_name,
                                     const std::string& source) {
  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + EscapeHtml(study_name) +
      "</title>\n<style>\nbody { font-family: sans-serif; margin: 1.5em; color: #222; }\n"
      "p.note { color: #555; }\n.controls { margin: 0.4em 0; }\n"
      ".controls input { width: 420px; vertical-align: middle; }\n</style>\n</head>\n<body>\n<h1>" +
      EscapeHtml(study_name) + "</h1>\n<p class=\"note\">" + EscapeHtml(source) + ": the scene once per load case (" +
      std::to_string(cases.size()) + "), each with the parameters the case sets.</p>\n";
  for (size_t k = 0; k < cases.size(); ++k) {
    const CaseDrawing& c = cases[k];
    out += "<h2>Load case " + EscapeHtml(c.load_case) + "</h2>\n<p class=\"note\">" + GridNote(c.drawing) + "</p>\n";
    out += MechanismFigureHtml({DrawingLayer{&c.drawing, c.load_case}}, "drawing-case-" + std::to_string(k));
  }
  return out + "</body>\n</html>\n";
}

}  // namespace mbopt::report
