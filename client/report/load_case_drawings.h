// Drawings of a study with load cases (spec::LoadCase): the scene once per
// case, with the parameters the case sets, each figure headed by the
// case's name. The report's "Mechanism" section overlays each case's
// initial and final design (MechanismSectionHtml hands such a study here);
// `mbopt draw` of such a study writes one page with every case.
#pragma once

#include <string>
#include <vector>

#include "client/report/mechanism_drawing.h"
#include "spec/scene_drawing.h"

namespace mbopt::report {

// The "Mechanism" section of `mechanism.cases` (and `mechanism.note`).
std::string LoadCaseSectionHtml(const MechanismDrawings& mechanism);

struct CaseDrawing {
  std::string load_case;
  spec::SceneDrawing drawing;
};
// A whole self-contained page, one figure per case in the given order.
std::string LoadCaseDrawingsPageHtml(const std::vector<CaseDrawing>& cases, const std::string& study_name,
                                     const std::string& source);

}  // namespace mbopt::report
