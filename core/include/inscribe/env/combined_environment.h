// Several environments as one (a cloud, a grid and some primitives): a ball's clearance is
// the smallest of its clearances to each, its interval [min of lowers, min of uppers].
#pragma once

#include <vector>

#include "inscribe/env/environment.h"

namespace inscribe {

class CombinedEnvironment final : public Environment {
 public:
  // The parts are not owned and must outlive this. None: every ball is clear.
  explicit CombinedEnvironment(std::vector<const Environment*> parts);

  // The smallest index any part reports. O(sum of the parts' costs).
  int FirstColliding(absl::Span<const Sphere> balls) const override;
  void Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                  absl::Span<ClearanceInterval> out) const override;
  double Lipschitz() const override;  // the largest part's

 private:
  std::vector<const Environment*> parts_;
};

}  // namespace inscribe
