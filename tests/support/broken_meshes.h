// A corpus of broken meshes as robot files ship them, built in code from clean solids so that
// each one's intended solid is known: open meshes, cracks, walls stored twice, overlapping
// bodies, inverted and mixed orientation, lone sheets, a millimetre mesh, non-manifold fins.
// For the repair ladder's tests, the CLI's and the benchmark (bench/mesh_repair_bench).
#pragma once

#include <string>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::testing {

struct BrokenMesh {
  std::string name;
  Mesh mesh;
  // The mildest repair level that makes it usable.
  MeshRepair needs = MeshRepair::kNone;
  // The solid the file means: the union of these clean closed meshes (a hole's patch is the
  // filler's choice: the intended solid holds away from it). Empty for meshes only a wrap makes
  // usable, whose solid is the wrap's.
  std::vector<Mesh> intended;
};

// An icosphere of 320 triangles cut in two along z = 0.1: the upper half's copies of the cut's
// vertices moved by `gap` (mesh units) in a fixed direction, so that the two halves meet along
// a crack `gap` wide; every vertex the halves share is duplicated.
Mesh CrackedSphere(double gap, double radius = 1.0);

// Two unit boxes side by side sharing the face x = 1, each stored closed: that face's two
// triangles appear twice, in opposite orders (as CAD exports store a wall between two bodies).
Mesh BoxesSharingAWall();

// The corpus (about 20 meshes). Sizes are about 1 (2 for the boxes) except the millimetre
// entries (about 1000).
std::vector<BrokenMesh> BrokenMeshCorpus();

// Entry `index`'s name as a test name ('-' as '_'), for suites parameterized over the corpus.
std::string BrokenMeshTestName(int index);

}  // namespace inscribe::testing
