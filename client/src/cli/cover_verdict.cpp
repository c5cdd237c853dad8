#include "cover_verdict.h"

#include "absl/strings/str_format.h"

namespace inscribe::cli {

std::string CoverVerdict(const CoverCertificate& c) {
  if (c.certified) return "certified: every point of the solid is in a sphere";
  if (c.uncovered_point) {
    const Vector3& p = *c.uncovered_point;
    return absl::StrFormat(
        "NOT certified: the point (%.10g %.10g %.10g), %.6g deep in the solid, is %.6g from the "
        "nearest sphere",
        p.x(), p.y(), p.z(), c.uncovered_depth, c.uncovered_gap);
  }
  return absl::StrFormat(
      "NOT certified: %d cells of side %.6g near the boundary are in no single sphere (no "
      "uncovered point found; a finer resolution may settle them)",
      c.failed_cells, c.resolution);
}

}  // namespace inscribe::cli
