// Whether a link's spheres cover its solid, from its elements' own certificates: the rule
// `inscribe evaluate --certify ROBOT SPHERES` applies link by link. A link's solid is the union
// of its elements (meshes, primitives); its spheres cover it when they cover every element.
#pragma once

#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::robot {

struct LinkCoverVerdict {
  bool certified = false;
  // With `certified`: a sound bound on how far the spheres reach outside the link's solid
  // (metres, >= 0): max over spheres i of min over elements e of i's protrusion past e, since
  // past the union a sphere reaches no farther than past any one element.
  double delta = 0.0;
  // The first element that is not proved covered (index into the link's elements), or unset.
  std::optional<int> failed_element;
};

// One element of the link: a mesh element's certificate of the link's `spheres` (CertifyCover
// against that element's solid), or a <sphere> element, which is covered when one of the
// spheres holds it (|c - c'| + r <= r'; a sufficient test) and from which sphere i protrudes
// by |c_i - c| + r_i - r.
struct ElementCover {
  std::optional<CoverCertificate> certificate;
  std::optional<Sphere> sphere;
};

// The verdict for `spheres` over `elements` (in the link's order). INVALID_ARGUMENT when an
// element has neither or both, or a certificate's protrusions are not one per sphere. A link
// with no elements has nothing to cover: certified, delta 0. O(#spheres * #elements).
absl::StatusOr<LinkCoverVerdict> CombineElementCovers(const std::vector<Sphere>& spheres,
                                                      const std::vector<ElementCover>& elements);

}  // namespace inscribe::robot
