#include "client/report/load_case_drawings.h"

#include <optional>
#include <utility>

#include "client/report/html_escape.h"
#include "client/report/number_format.h"

namespace mbopt::report {
namespace {

using spec::SceneDrawing;

// What a figure shows: a motion, or a lumped scene's layout.
std::string GridNote(const SceneDrawing& drawing) {
  return drawing.schematic ? std::string("a schematic (a lumped scene: its layout, not a motion)")
                           : std::to_string(drawing.times_s.size()) + " instants of the time grid";
}

// One slider and play button for every case's figure: each shows its frame
// nearest the shared time (its own slider still moves it alone). The times
// are the frames of the longest grid; "#time=T" in the page's address opens
// every figure at T. The controls go above the figures, the script after
// them (it calls the figures' showTime).
struct SharedTimeControl {
  std::string controls;
  std::string script;
};

// `figures`: each animated figure's id and its drawing of most instants.
SharedTimeControl SharedTime(const std::vector<std::pair<std::string, const SceneDrawing*>>& figures) {
  if (figures.size() < 2) return {};
  const SceneDrawing* longest = figures.front().second;
  for (const auto& [id, drawing] : figures) {
    if (drawing->times_s.size() > longest->times_s.size()) longest = drawing;
  }
  const std::vector<size_t> frames = FrameInstants(longest->times_s.size());
  std::string times, ids;
  for (const size_t f : frames) times += (times.empty() ? "\"" : ",\"") + FormatValue(longest->times_s[f], 6) + "\"";
  for (const auto& [id, drawing] : figures) ids += (ids.empty() ? "\"" : ",\"") + EscapeHtml(id) + "\"";
  SharedTimeControl control;
  control.controls =
      "<div class=\"controls\" id=\"cases-time\">Every case: <button type=\"button\">Play</button> "
      "<input type=\"range\" min=\"0\" max=\"" +
      std::to_string(frames.size() - 1) +
      "\" value=\"0\" step=\"1\" style=\"width: 420px; vertical-align: middle\"> <span class=\"time\">t = " +
      FormatValue(longest->times_s[frames.front()], 6) + " s</span></div>\n";
  control.script =
      "<script>(function(){var ids=[" + ids + "];var times=[" + times +
      "];var root=document.getElementById(\"cases-time\");var slider=root.querySelector(\"input\");"
      "var button=root.querySelector(\"button\");var label=root.querySelector(\".time\");var shown=0,timer=null;"
      "function show(i){shown=i;slider.value=i;label.textContent=\"t = \"+times[i]+\" s\";"
      "ids.forEach(function(id){var figure=document.getElementById(id);"
      "if(figure&&figure.showTime)figure.showTime(Number(times[i]));});}"
      "slider.addEventListener(\"input\",function(){show(Number(slider.value));});"
      "button.addEventListener(\"click\",function(){if(timer!==null){clearInterval(timer);timer=null;"
      "button.textContent=\"Play\";return;}button.textContent=\"Pause\";timer=setInterval(function(){"
      "show((shown+1)%times.length);},60);});"
      "var asked=/time=([-+0-9.eE]+)/.exec(location.hash);if(asked){var t=Number(asked[1]),best=0;"
      "for(var i=1;i<times.length;i++){if(Math.abs(Number(times[i])-t)<Math.abs(Number(times[best])-t))best=i;}"
      "show(best);}})();</script>\n";
  return control;
}

// Whether a drawing's figure is animated (more than one instant drawn).
bool Animated(const SceneDrawing& drawing) { return !drawing.schematic && drawing.points_m.size() > 1; }

}  // namespace

std::string LoadCaseSectionHtml(const MechanismDrawings& mechanism) {
  std::string out = "<h2>Mechanism</h2>\n";
  bool intro = false;
  // One scale and window for every case: each figure's axes hold the
  // others' drawings too.
  std::vector<const SceneDrawing*> every_case;
  for (const LoadCaseDrawings& c : mechanism.cases) {
    if (c.initial) every_case.push_back(&*c.initial);
    if (c.final) every_case.push_back(&*c.final);
  }
  std::vector<std::pair<std::string, const SceneDrawing*>> animated;
  std::string figures;
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
    figures += "<h3>Load case " + EscapeHtml(c.name) + "</h3>\n";
    std::vector<DrawingLayer> layers;
    if (c.initial) layers.push_back(DrawingLayer{&*c.initial, "initial design, " + c.name, "#7a7a7a", "#e6e6e6", 0.75});
    if (c.final) layers.push_back(DrawingLayer{&*c.final, "final design, " + c.name, "#1f4e9a", "#c9d8f0", 1.0});
    // Ids unique on the page: one figure per case.
    const std::string id = "mechanism-case-" + std::to_string(k);
    if (!layers.empty()) figures += MechanismFigureHtml(layers, id, every_case);
    const SceneDrawing* longest = nullptr;
    for (const DrawingLayer& layer : layers) {
      if (Animated(*layer.drawing) && (longest == nullptr || layer.drawing->times_s.size() > longest->times_s.size())) {
        longest = layer.drawing;
      }
    }
    if (longest != nullptr) animated.emplace_back(id, longest);
    if (!c.note.empty()) figures += "<p class=\"note\">" + EscapeHtml(c.note) + "</p>\n";
  }
  const SharedTimeControl shared = SharedTime(animated);
  out += shared.controls + figures + shared.script;
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
  std::vector<const SceneDrawing*> every_case;
  for (const CaseDrawing& c : cases) every_case.push_back(&c.drawing);
  std::vector<std::pair<std::string, const SceneDrawing*>> animated;
  std::string figures;
  for (size_t k = 0; k < cases.size(); ++k) {
    const CaseDrawing& c = cases[k];
    const std::string id = "drawing-case-" + std::to_string(k);
    figures += "<h2>Load case " + EscapeHtml(c.load_case) + "</h2>\n<p class=\"note\">" + GridNote(c.drawing) + "</p>\n";
    figures += MechanismFigureHtml({DrawingLayer{&c.drawing, c.load_case}}, id, every_case);
    if (Animated(c.drawing)) animated.emplace_back(id, &c.drawing);
  }
  const SharedTimeControl shared = SharedTime(animated);
  return out + shared.controls + figures + shared.script + "</body>\n</html>\n";
}

}  // namespace mbopt::report
