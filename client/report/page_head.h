// The opening every report page shares: doctype, title, the page's own
// style sheet, the study's name as heading and its description.
#pragma once

#include <string>
#include <string_view>

namespace mbopt::report {

// `study_name` empty reads "(unnamed study)"; `style_css` goes inline.
std::string PageHeadHtml(const std::string& study_name, const std::string& description, std::string_view style_css);

}  // namespace mbopt::report
