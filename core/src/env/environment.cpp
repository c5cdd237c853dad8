#include "inscribe/env/environment.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace inscribe {

absl::Status CheckClearanceRequest(const ClearanceRequest& request) {
  if (!(request.tolerance >= 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "tolerance ", request.tolerance, " must be >= 0 (metres; +infinity: O(1) bounds)"));
  }
  if (!(request.max_distance > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("max_distance ", request.max_distance,
                                                   " must be > 0 (metres; +infinity: no cap)"));
  }
  return absl::OkStatus();
}

}  // namespace inscribe
