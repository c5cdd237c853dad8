#include "inscribe/robot/link_cover.h"

#include <algorithm>
#include <limits>

#include "absl/strings/str_cat.h"

namespace inscribe::robot {

absl::StatusOr<LinkCoverVerdict> CombineElementCovers(const std::vector<Sphere>& spheres,
                                                      const std::vector<ElementCover>& elements) {
  LinkCoverVerdict verdict;
  verdict.certified = true;
  // Per sphere, the least protrusion past any element so far.
  std::vector<double> least(spheres.size(), std::numeric_limits<double>::infinity());
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const ElementCover& element = elements[e];
    if (element.certificate.has_value() == element.sphere.has_value()) {
      return absl::InvalidArgumentError(
          absl::StrCat("element ", e, " needs a certificate or a sphere, not both or neither"));
    }
    bool covered = false;
    if (element.certificate) {
      const CoverCertificate& c = *element.certificate;
      if (c.protrusions.size() != spheres.size()) {
        return absl::InvalidArgumentError(absl::StrCat("element ", e, ": ", c.protrusions.size(),
                                                       " protrusions for ", spheres.size(),
                                                       " spheres"));
      }
      covered = c.certified;
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        least[i] = std::min(least[i], c.protrusions[i]);
      }
    } else {
      const Sphere& s = *element.sphere;
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        const double gap = (spheres[i].center - s.center).norm();
        covered = covered || gap + s.radius <= spheres[i].radius;
        least[i] = std::min(least[i], gap + spheres[i].radius - s.radius);
      }
    }
    if (!covered && !verdict.failed_element) verdict.failed_element = static_cast<int>(e);
  }
  verdict.certified = !verdict.failed_element.has_value();
  if (!elements.empty()) {
    for (double p : least) verdict.delta = std::max(verdict.delta, p);
  }
  return verdict;
}

}  // namespace inscribe::robot
