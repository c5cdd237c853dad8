// The shell every `inscribe view` page shares: one self-contained HTML document with three.js,
// its OrbitControls, the page's style sheet and one page script inlined, and the page's data as
// JSON in <script type="application/json" id="inscribe-data">. Private to the view library.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace inscribe::view {

// x rounded to `digits` significant decimal digits, as the double whose shortest form (which
// nlohmann::json writes) has at most that many digits: 7 for what WebGL draws (float).
double RoundSignificant(double x, int digits);

// `text` as HTML text or attribute value: markup characters escaped, and invalid UTF-8 (a
// file name's bytes) replaced by U+FFFD as in the data element.
std::string EscapeHtml(const std::string& text);

// The page: `title` in the tab, `data` for the script, `script` (named `script_name` in
// errors) after three.js. INTERNAL when an inlined file would end its element early (a script
// containing "</script", a licence containing "--"): a build problem.
absl::StatusOr<std::string> SelfContainedPage(const nlohmann::json& data, const std::string& title,
                                              absl::string_view script_name,
                                              absl::string_view script);

}  // namespace inscribe::view
