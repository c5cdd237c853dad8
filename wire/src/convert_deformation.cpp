// The settings of an UpdateDeformation request, both ways (convert.h).
#include "inscribe/wire/convert.h"

namespace inscribe::wire {

void DeformationSettingsToProto(const DeformationSettings& settings,
                                v1::UpdateDeformationRequest* out) {
  out->set_xi(settings.options.xi);
  out->set_strict(settings.options.strict);
  out->set_interpolated_normal(settings.options.direction == ContactDirection::kInterpolatedNormal);
  out->set_bounds(settings.bounds);
  out->set_store(settings.store);
}

absl::StatusOr<DeformationSettings> DeformationSettingsFromProto(
    const v1::UpdateDeformationRequest& request) {
  DeformationSettings settings;
  settings.options.xi = request.xi();
  settings.options.strict = request.strict();
  settings.options.direction = request.interpolated_normal() ? ContactDirection::kInterpolatedNormal
                                                             : ContactDirection::kCarriedFrame;
  if (absl::Status s = CheckDeformationOptions(settings.options); !s.ok()) return s;
  settings.bounds = request.bounds();
  settings.store = request.store();
  return settings;
}

}  // namespace inscribe::wire
