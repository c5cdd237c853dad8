// What the distance and scene bindings share: hierarchies from Python values, (N, 7) poses,
// and the certified object handle.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"

namespace inscribe::python {

namespace py = pybind11;

using HierarchyPtr = std::shared_ptr<const SphereHierarchy>;

// The volume named "sphere" or "rss" (HierarchyVolumeName); ValueError otherwise.
HierarchyVolume VolumeOf(const std::string& name);

// A Hierarchy as given, or one built (sphere volumes, the service's default) from a SphereSet
// or an (N, 4) array.
HierarchyPtr HierarchyOf(py::handle value);

// Poses as (N, 7) float64 rows [qw, qx, qy, qz, tx, ty, tz] (a (7,) array is one row), each
// normalised by core's rule (NormalizedPose); ValueError naming the row otherwise.
std::vector<RigidPose> PosesOf(py::handle value, const char* name);

// inscribe.CertifiedObject: the hierarchies it owns and the core object pointing into them.
struct CertifiedObjectHandle {
  HierarchyPtr internal, cover;
  CertifiedObject object;
};

}  // namespace inscribe::python
