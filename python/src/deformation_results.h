// What inscribe.Deformer and inscribe.Client.update_deformation share: the settings as Python
// callers give them, and the moved spheres as Python sees them.
#pragma once

#include <memory>
#include <optional>

#include "inscribe/medial/sphere_deformation.h"
#include "sphere_set.h"

namespace inscribe::python {

// Core's options with xi (mesh units; nullopt: core's default), strict, and the interpolated
// normal as the direction when asked; the rest core's defaults.
DeformationOptions DeformationOptionsOf(std::optional<double> xi, bool strict,
                                        bool interpolated_normal);

// An update's spheres as a SphereSet: kind "internal", contacts, reference_index, and the
// figures (xi, max_protrusion, shrunk, dropped, closest_point_queries, max_shrink_steps,
// seconds) as .stats.
std::shared_ptr<PySphereSet> DeformedSphereSet(DeformedSpheres moved);

}  // namespace inscribe::python
