#include "client/report/page_head.h"

#include "client/report/html_escape.h"

namespace mbopt::report {

std::string PageHeadHtml(const std::string& study_name, const std::string& description, std::string_view style_css) {
  const std::string name = study_name.empty() ? std::string("(unnamed study)") : study_name;
  std::string out;
  out += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  out += "<title>mbopt report: " + EscapeHtml(name) + "</title>\n";
  out += "<style>" + std::string(style_css) + "</style>\n</head>\n<body>\n";
  out += "<h1>" + EscapeHtml(name) + "</h1>\n";
  if (!description.empty()) out += "<p class=\"description\">" + EscapeHtml(description) + "</p>\n";
  return out;
}

}  // namespace mbopt::report
