#include "inscribe/env/combined_environment.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

namespace inscribe {

CombinedEnvironment::CombinedEnvironment(std::vector<const Environment*> parts)
    : parts_(std::move(parts)) {}

int CombinedEnvironment::FirstColliding(absl::Span<const Sphere> balls) const {
  int first = -1;
  for (const Environment* part : parts_) {
    const int found = part->FirstColliding(first < 0 ? balls : balls.subspan(0, first));
    if (found >= 0) first = found;
    if (first == 0) break;
  }
  return first;
}

void CombinedEnvironment::Clearances(absl::Span<const Sphere> balls,
                                     const ClearanceRequest& request,
                                     absl::Span<ClearanceInterval> out) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (ClearanceInterval& interval : out) interval = {kInf, kInf};
  std::vector<ClearanceInterval> part_out(balls.size());
  for (const Environment* part : parts_) {
    part->Clearances(balls, request, absl::MakeSpan(part_out));
    for (std::size_t i = 0; i < balls.size(); ++i) {
      out[i].lower = std::min(out[i].lower, part_out[i].lower);
      out[i].upper = std::min(out[i].upper, part_out[i].upper);
    }
  }
}

double CombinedEnvironment::Lipschitz() const {
  double largest = 1.0;
  for (const Environment* part : parts_) largest = std::max(largest, part->Lipschitz());
  return largest;
}

}  // namespace inscribe
