// The exact distance between two posed closed solids, with FCL (Debian's libfcl-dev) as the
// oracle that certified distance intervals are checked and timed against. FCL measures between
// triangle surfaces; the solids are 0 apart when the surfaces touch or cross, or when one
// solid holds a whole shell of the other (no surface crossing, so a shell with one vertex
// inside the other solid lies inside it; the solid's own inside test decides).
#pragma once

#include <fcl/fcl.h>

#include <memory>
#include <vector>

#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/solid/solid.h"

namespace inscribe::testing {

using FclMesh = fcl::BVHModel<fcl::OBBRSSd>;

// FCL's OBBRSS tree over the mesh's triangles (same vertices, same frame).
std::shared_ptr<FclMesh> BuildFclMesh(const Mesh& mesh);

// The pose as FCL's transform: the rotation of the normalised quaternion.
fcl::Transform3d ToFcl(const RigidPose& pose);

// One solid as the oracle sees it. `solid` is not owned and must outlive this.
struct FclSolid {
  const Solid* solid = nullptr;
  std::shared_ptr<FclMesh> fcl;
  std::vector<Eigen::Index> shell_vertices;  // one vertex per connected shell of the mesh
};

FclSolid MakeFclSolid(const Solid& solid);

enum class SolidContact {
  kApart,      // FCL's surface distance is the solids' distance
  kSurfaces,   // fcl::collide: the surfaces touch or cross
  kContained,  // no surface contact, but a shell of one lies inside the other solid
};

struct ExactSolidDistance {
  double distance = 0.0;  // 0 unless kApart; mesh units, FCL's rounding included
  SolidContact contact = SolidContact::kApart;
};

// fcl::collide, then the shells' inside test, then fcl::distance with FCL's exact settings
// (rel_err = abs_err = 0).
ExactSolidDistance SolidDistance(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                                 const RigidPose& pose_b);

// fcl::collide alone: do the two surfaces touch or cross?
bool SurfacesCollide(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                     const RigidPose& pose_b);

// fcl::distance alone (exact settings), the call the benchmark times.
double SurfaceDistance(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                       const RigidPose& pose_b);

}  // namespace inscribe::testing
