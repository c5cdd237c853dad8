// Sphere sets and poses for tests of hierarchies and separation distance.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::testing {

// n overlapping balls: centres in clusters along a random sheet-like layout inside the unit
// cube (like medial sheets), radii in [0.02, 0.12]. Deterministic per seed.
std::vector<Sphere> RandomSpheres(int n, std::uint64_t seed);

// n balls with centres uniform in [0, side]^3 and radii uniform in [rmin, rmax].
std::vector<Sphere> RandomBalls(int n, double side, double rmin, double rmax, std::uint64_t seed);

// A uniformly random rotation and a translation uniform in the ball of radius `spread`.
RigidPose RandomPose(std::mt19937_64& rng, double spread);

// The medial spheres of data/<name> at a voxel size of 1/30 of its bounding-box diagonal
// (a few hundred spheres), made once per process. Empty (and a test failure) on error.
const std::vector<Sphere>& RealSphereSet(const std::string& name);

}  // namespace inscribe::testing
