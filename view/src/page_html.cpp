#include "page_html.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "viewer_assets.h"

namespace inscribe::view {
namespace {

// Whether `text`, inlined in a raw-text element <tag> (script or style), would end it early:
// the HTML parser closes the element at the first "</tag" whatever the case. In a script,
// "<!--" could also switch the parser into its escaped states, where "</script" is no longer
// the only way out; neither occurs in the files inlined here.
bool EndsElementEarly(absl::string_view text, absl::string_view tag) {
  const std::string lower = absl::AsciiStrToLower(text);
  return absl::StrContains(lower, absl::StrCat("</", tag)) ||
         (tag == "script" && absl::StrContains(lower, "<!--"));
}

}  // namespace

double RoundSignificant(double x, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, x);
  return std::strtod(text, nullptr);
}

std::string EscapeHtml(const std::string& text) {
  const std::string valid =
      nlohmann::json::parse(
          nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))
          .get<std::string>();
  return absl::StrReplaceAll(
      valid, {{"&", "&amp;"}, {"<", "&lt;"}, {">", "&gt;"}, {"\"", "&quot;"}, {"'", "&#39;"}});
}

absl::StatusOr<std::string> SelfContainedPage(const nlohmann::json& data, const std::string& title,
                                              absl::string_view script_name,
                                              absl::string_view script) {
  for (const auto& [name, text] :
       {std::pair{absl::string_view("three.min.js"), ThreeJs()},
        std::pair{absl::string_view("OrbitControls.js"), OrbitControlsJs()},
        std::pair{script_name, script}}) {
    if (EndsElementEarly(text, "script")) {
      return absl::InternalError(
          absl::StrCat(name, " contains </script or <!--: it cannot be inlined in the page"));
    }
  }
  if (EndsElementEarly(ViewPageCss(), "style")) {
    return absl::InternalError("view_page.css contains </style: it cannot be inlined");
  }
  if (absl::StrContains(ThreeJsLicense(), "--")) {
    return absl::InternalError("three's licence contains --: it cannot go in an HTML comment");
  }
  // '<' only occurs inside JSON strings, where \u003c means the same: nothing in the data can
  // close the script element. Invalid UTF-8 (in a file name) becomes U+FFFD.
  const std::string json = absl::StrReplaceAll(
      data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), {{"<", "\\u003c"}});
  std::string html;
  html.reserve(ThreeJs().size() + OrbitControlsJs().size() + json.size() + 64 * 1024);
  absl::StrAppend(&html,
                  "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                  "<meta name=\"generator\" content=\"inscribe view\">\n<title>",
                  EscapeHtml(title), " - inscribe view</title>\n");
  absl::StrAppend(&html,
                  "<!--\nThis page inlines three.js 0.147.0 (build/three.min.js and "
                  "examples/js/controls/OrbitControls.js of the npm package three), "
                  "distributed under the following licence:\n\n",
                  ThreeJsLicense(), "\n-->\n");
  absl::StrAppend(&html, "<style>\n", ViewPageCss(), "</style>\n</head>\n<body>\n",
                  "<aside id=\"panel\"></aside>\n<main id=\"viewport\"></main>\n",
                  "<pre id=\"error\" hidden></pre>\n");
  absl::StrAppend(&html, "<script type=\"application/json\" id=\"inscribe-data\">", json,
                  "</script>\n");
  absl::StrAppend(&html, "<script>\n", ThreeJs(), "\n</script>\n");
  absl::StrAppend(&html, "<script>\n", OrbitControlsJs(), "\n</script>\n");
  absl::StrAppend(&html, "<script>\n", script, "\n</script>\n</body>\n</html>\n");
  return html;
}

}  // namespace inscribe::view
