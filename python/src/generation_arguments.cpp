#include "generation_arguments.h"

#include "status_errors.h"

namespace inscribe::python {

SphereSetParameters SphereSetParametersOf(const GenerateArguments& a) {
  SphereSetParameters parameters;
  parameters.kind = ValueOrRaise(ParseSphereSetKind(a.kind));
  if (a.selection) parameters.selection = ValueOrRaise(ParseSphereSelection(*a.selection));
  parameters.max_spheres = a.max_spheres;
  parameters.voxel_size = a.voxel_size;
  Override(parameters.medial.object_angle, a.object_angle);
  Override(parameters.medial.epsilon, a.epsilon);
  Override(parameters.medial.samples, a.samples);
  Override(parameters.medial.subdivide_boundary, a.subdivide_boundary);
  Override(parameters.medial.max_voxels, a.max_voxels);
  Override(parameters.dilation.growth, a.dilation_growth);
  parameters.max_protrusion = a.max_protrusion;
  Override(parameters.cover_resolution, a.cover_resolution);
  parameters.evaluate = a.evaluate;
  Override(parameters.quality.surface_samples, a.quality_samples);
  OkOrRaise(CheckSphereSetParameters(parameters));
  return parameters;
}

}  // namespace inscribe::python
