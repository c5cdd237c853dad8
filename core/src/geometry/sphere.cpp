#include "inscribe/geometry/sphere.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "base/format_double.h"

namespace inscribe {

absl::Status CheckSphere(const Sphere& sphere, std::size_t index) {
  static constexpr const char* kAxis[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(sphere.center[k])) {
      return absl::InvalidArgumentError(absl::StrCat("sphere ", index, ": center ", kAxis[k], " ",
                                                     internal::FormatDouble(sphere.center[k]),
                                                     " is not finite"));
    }
  }
  if (!std::isfinite(sphere.radius)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sphere ", index, ": radius ", internal::FormatDouble(sphere.radius), " is not finite"));
  }
  if (!(sphere.radius > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sphere ", index, ": radius ", internal::FormatDouble(sphere.radius), " is not positive"));
  }
  return absl::OkStatus();
}

absl::Status CheckSpheres(const std::vector<Sphere>& spheres) {
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    if (absl::Status s = CheckSphere(spheres[i], i); !s.ok()) return s;
  }
  return absl::OkStatus();
}

}  // namespace inscribe
