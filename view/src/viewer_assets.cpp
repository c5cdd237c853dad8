#include "viewer_assets.h"

#include <cstddef>

// Defined in the sources that inscribe_embed_files generates (client/CMakeLists.txt).
namespace inscribe::view::embedded {
extern const unsigned char kThreeMinJs[];
extern const std::size_t kThreeMinJsSize;
extern const unsigned char kOrbitControlsJs[];
extern const std::size_t kOrbitControlsJsSize;
extern const unsigned char kThreeLicense[];
extern const std::size_t kThreeLicenseSize;
extern const unsigned char kViewPageJs[];
extern const std::size_t kViewPageJsSize;
extern const unsigned char kRobotViewPageJs[];
extern const std::size_t kRobotViewPageJsSize;
extern const unsigned char kViewPageCss[];
extern const std::size_t kViewPageCssSize;
}  // namespace inscribe::view::embedded

namespace inscribe::view {
namespace {

absl::string_view View(const unsigned char* bytes, std::size_t size) {
  return absl::string_view(reinterpret_cast<const char*>(bytes), size);
}

}  // namespace

absl::string_view ThreeJs() { return View(embedded::kThreeMinJs, embedded::kThreeMinJsSize); }
absl::string_view OrbitControlsJs() {
  return View(embedded::kOrbitControlsJs, embedded::kOrbitControlsJsSize);
}
absl::string_view ThreeJsLicense() {
  return View(embedded::kThreeLicense, embedded::kThreeLicenseSize);
}
absl::string_view ViewPageJs() { return View(embedded::kViewPageJs, embedded::kViewPageJsSize); }
absl::string_view RobotViewPageJs() {
  return View(embedded::kRobotViewPageJs, embedded::kRobotViewPageJsSize);
}
absl::string_view ViewPageCss() { return View(embedded::kViewPageCss, embedded::kViewPageCssSize); }

}  // namespace inscribe::view
