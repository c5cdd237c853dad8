// The size of the voxel grid medial-sphere generation lays over a mesh: the one formula that
// GenerateMedialSpheres builds its grid by and that a caller estimating a generation's cost
// (the service's memory budget and its --max-voxels check) counts by.
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe {

// Cells along each axis of the grid of cubes of side `voxel_size` (mesh units, > 0) that
// covers a bounding box of `extent` (BoundingBox::extent): ceil(extent / voxel_size), at
// least 1, in double so that a tiny voxel size cannot overflow. Their product is the grid's
// voxel count, which MedialSphereOptions::max_voxels bounds. O(1).
Vector3 VoxelGridCells(const Vector3& extent, double voxel_size);

}  // namespace inscribe
