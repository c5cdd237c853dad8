// Deformation sequences of the demo meshes, for tests and benchmarks of sphere updates (paper
// Section V): smooth maps of vertex positions that keep the triangles, of the four kinds the
// update method must be judged on.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe::sequences {

enum class DeformationKind {
  // Articulation: the far part of the model along its longest bounding-box axis turns by up
  // to 60 degrees in the plane of the longest and middle axes; a bend zone around 60% of the
  // length (a quarter of it or more, wide enough not to fold) bends along circular arcs whose
  // angle blends linearly from 0 to the full turn (Barr's bend). Near volume-preserving.
  kBend,
  // Volume-preserving elastic deformation: a rotation about the longest axis (through the box
  // centre) by an angle proportional to the position along it, up to 90 degrees end to end.
  // Its Jacobian has determinant 1.
  kTwist,
  // A rotation (up to 90 degrees about a fixed oblique axis through the box centre) and a
  // translation (up to 0.6 of the box diagonal).
  kRigid,
  // A local shrink that does not preserve local feature size: points within a ball around the
  // box centre (radius 0.35 of the longest extent) move towards its centre, by up to 45% of
  // their distance at the centre, fading smoothly to 0 at its surface. One-to-one (the radial
  // map stays increasing), so the surface never folds.
  kPinch,
};

// "bend", "twist", "rigid", "pinch".
const char* DeformationKindName(DeformationKind kind);
absl::StatusOr<DeformationKind> ParseDeformationKind(const std::string& name);
std::vector<DeformationKind> AllDeformationKinds();

// The reference's vertices (#V by 3) deformed by `kind` at amount t in [0, 1] (0 = unchanged,
// 1 = the full deformation above). The frame depends only on the reference's bounding box.
Vertices Deform(const Vertices& reference, DeformationKind kind, double t);

// Frames 1..frames of a sequence: frame k at t = k / frames (frame 0, the reference, is not
// included). #frames entries, each #V by 3.
std::vector<Vertices> DeformationSequence(const Vertices& reference, DeformationKind kind,
                                          int frames);

}  // namespace inscribe::sequences
