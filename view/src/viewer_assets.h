// The files `inscribe view` inlines in its page, embedded in the binary at build time
// (cmake/ThreeJs.cmake, cmake/EmbedFiles.cmake), so the page needs no network: three.js
// 0.147.0 and its OrbitControls from the npm package `three` (MIT licence), three's licence
// text, and the page's own script and style sheet (view_page.js, view_page.css), and the robot
// page's script (robot_view_page.js).
#pragma once

#include "absl/strings/string_view.h"

namespace inscribe::view {

absl::string_view ThreeJs();          // build/three.min.js: defines the global THREE
absl::string_view OrbitControlsJs();  // examples/js/controls/OrbitControls.js: THREE.OrbitControls
absl::string_view ThreeJsLicense();   // three's LICENSE file (MIT)
absl::string_view ViewPageJs();       // view_page.js
absl::string_view RobotViewPageJs();  // robot_view_page.js
absl::string_view ViewPageCss();      // view_page.css

}  // namespace inscribe::view
