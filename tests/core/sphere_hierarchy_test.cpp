#include "inscribe/distance/sphere_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "inscribe/distance/separation_distance.h"
#include "support/sphere_sets.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::RandomPose;
using testing::RandomSpheres;
using testing::RealSphereSet;

constexpr HierarchyVolume kVolumes[] = {HierarchyVolume::kRss, HierarchyVolume::kSphere};

// Every internal node's volume holds every sphere below it, checked against the node's own
// definition (distance to the rectangle, or to the centre) for each (node, sphere) pair.
void ExpectNodesBoundTheirSpheres(const SphereHierarchy& h) {
  std::vector<std::int32_t> below;
  int failures = 0;
  for (std::int32_t node = 0; node < static_cast<std::int32_t>(h.num_nodes()); ++node) {
    below.clear();
    std::vector<HierarchyRef> stack = {node};
    while (!stack.empty()) {
      const HierarchyRef ref = stack.back();
      stack.pop_back();
      if (IsLeaf(ref)) {
        below.push_back(LeafSphere(ref));
      } else {
        stack.push_back(h.left(ref));
        stack.push_back(h.right(ref));
      }
    }
    ASSERT_GE(below.size(), 2u);
    for (const std::int32_t i : below) {
      const Sphere& s = h.spheres()[static_cast<std::size_t>(i)];
      double excess;
      if (h.volume() == HierarchyVolume::kRss) {
        Rss point;
        point.origin = s.center;
        Vector3 pa, pb;
        excess = RectangleDistance(h.rss(node), point, &pa, &pb) + s.radius - h.rss(node).radius;
      } else {
        const Sphere& b = h.bounding_sphere(node);
        excess = (s.center - b.center).norm() + s.radius - b.radius;
      }
      if (excess > 1e-12 && failures++ < 5) {
        ADD_FAILURE() << HierarchyVolumeName(h.volume()) << " node " << node << ": sphere " << i
                      << " sticks out by " << excess;
      }
    }
    // The query's record of the node: the same children, the sphere around the volume holding
    // every sphere below, and a range of ordered_spheres() holding exactly those spheres.
    const SphereHierarchy::Slot& slot = h.slot(node);
    EXPECT_EQ(slot.left, h.left(node));
    EXPECT_EQ(slot.right, h.right(node));
    ASSERT_EQ(slot.count, static_cast<std::int32_t>(below.size()));
    std::vector<std::int32_t> in_range(h.leaf_order().begin() + slot.first,
                                       h.leaf_order().begin() + slot.first + slot.count);
    std::sort(in_range.begin(), in_range.end());
    std::sort(below.begin(), below.end());
    EXPECT_EQ(in_range, below) << "node " << node;
    for (const std::int32_t i : below) {
      const Sphere& s = h.spheres()[static_cast<std::size_t>(i)];
      const double excess = (s.center - slot.center).norm() + s.radius - slot.radius;
      if (excess > 1e-12 && failures++ < 5) {
        ADD_FAILURE() << "slot of node " << node << ": sphere " << i << " sticks out by " << excess;
      }
    }
  }
  // Leaves: the sphere itself, found at its place in ordered_spheres().
  for (std::size_t i = 0; i < h.spheres().size(); ++i) {
    const SphereHierarchy::Slot& slot = h.slot(-1 - static_cast<std::int32_t>(i));
    const Sphere& ordered = h.ordered_spheres()[static_cast<std::size_t>(slot.first)];
    EXPECT_EQ(slot.count, 1);
    EXPECT_EQ(h.leaf_order()[static_cast<std::size_t>(slot.first)], static_cast<std::int32_t>(i));
    EXPECT_EQ(slot.center, h.spheres()[i].center);
    EXPECT_EQ(slot.radius, h.spheres()[i].radius);
    EXPECT_EQ(ordered.center, h.spheres()[i].center);
    EXPECT_EQ(ordered.radius, h.spheres()[i].radius);
  }
  EXPECT_EQ(failures, 0);
}

TEST(SphereHierarchy, NodesBoundTheirSpheresOnRandomSets) {
  for (HierarchyVolume volume : kVolumes) {
    for (int seed = 1; seed <= 5; ++seed) {
      absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(RandomSpheres(300, seed), volume);
      ASSERT_TRUE(h.ok()) << h.status();
      EXPECT_EQ(h->num_nodes(), 299u);
      ExpectNodesBoundTheirSpheres(*h);
      EXPECT_LE(h->depth(), 40);
    }
  }
}

TEST(SphereHierarchy, NodesBoundTheirSpheresOnRealSets) {
  for (const char* name : {"eight.off", "knot1.off", "fandisk.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const std::vector<Sphere> spheres = RealSphereSet(name);
    for (HierarchyVolume volume : kVolumes) {
      absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
      ASSERT_TRUE(h.ok()) << h.status();
      ExpectNodesBoundTheirSpheres(*h);
    }
  }
}

TEST(SphereHierarchy, DegenerateSets) {
  for (HierarchyVolume volume : kVolumes) {
    // One sphere: no internal node, the root is its leaf.
    absl::StatusOr<SphereHierarchy> one = SphereHierarchy::Build({{Vector3(1, 2, 3), 0.5}}, volume);
    ASSERT_TRUE(one.ok());
    EXPECT_EQ(one->num_nodes(), 0u);
    EXPECT_TRUE(IsLeaf(one->root()));
    // Coincident centres (the mean split puts all on one side) and collinear ones.
    std::vector<Sphere> same(17, Sphere{Vector3(1, 1, 1), 0.3});
    for (std::size_t i = 0; i < same.size(); ++i) same[i].radius = 0.1 + 0.01 * i;
    absl::StatusOr<SphereHierarchy> coincident = SphereHierarchy::Build(same, volume);
    ASSERT_TRUE(coincident.ok());
    ExpectNodesBoundTheirSpheres(*coincident);
    EXPECT_LE(coincident->depth(), 6);
    std::vector<Sphere> line;
    for (int i = 0; i < 50; ++i) line.push_back({Vector3(0.1 * i, 0, 0), 0.05});
    absl::StatusOr<SphereHierarchy> collinear = SphereHierarchy::Build(line, volume);
    ASSERT_TRUE(collinear.ok());
    ExpectNodesBoundTheirSpheres(*collinear);
  }
}

TEST(SphereHierarchy, RefusesBadSpheres) {
  for (HierarchyVolume volume : kVolumes) {
    EXPECT_FALSE(SphereHierarchy::Build({}, volume).ok());
    EXPECT_FALSE(SphereHierarchy::Build({{Vector3(0, 0, 0), 0.0}}, volume).ok());
    EXPECT_FALSE(SphereHierarchy::Build({{Vector3(0, 0, 0), -1.0}}, volume).ok());
    absl::StatusOr<SphereHierarchy> nan = SphereHierarchy::Build(
        {{Vector3(0, 0, 0), 1.0}, {Vector3(std::nan(""), 0, 0), 1.0}}, volume);
    ASSERT_FALSE(nan.ok());
    EXPECT_NE(nan.status().message().find("sphere 1"), std::string::npos) << nan.status();
  }
}

// Serialize -> Deserialize gives the same bytes and the same answers; every truncation and
// trailing byte is refused; random corruption is refused or, when it still describes a valid
// hierarchy (a flipped low bit of a padded radius, say), still gives exact answers.
TEST(SphereHierarchy, SerialisationRoundTripsAndRefusesCorruption) {
  const std::vector<Sphere> spheres = RandomSpheres(60, 9);
  const std::vector<Sphere> other = RandomSpheres(40, 10);
  std::mt19937_64 rng(3);
  for (HierarchyVolume volume : kVolumes) {
    absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
    absl::StatusOr<SphereHierarchy> hb = SphereHierarchy::Build(other, volume);
    ASSERT_TRUE(h.ok() && hb.ok());
    const std::string bytes = h->Serialize();
    absl::StatusOr<SphereHierarchy> back = SphereHierarchy::Deserialize(bytes);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(back->Serialize(), bytes);
    EXPECT_EQ(back->depth(), h->depth());
    ExpectNodesBoundTheirSpheres(*back);  // the derived records are rebuilt too

    for (std::size_t n = 0; n < bytes.size(); n += (n < 64 ? 1 : 37)) {
      EXPECT_FALSE(SphereHierarchy::Deserialize(bytes.substr(0, n)).ok()) << n;
    }
    EXPECT_FALSE(SphereHierarchy::Deserialize(bytes + "x").ok());
    EXPECT_FALSE(SphereHierarchy::Deserialize("garbage").ok());
    EXPECT_FALSE(SphereHierarchy::Deserialize(std::string(4096, '\xff')).ok());

    int accepted = 0;
    std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
    std::uniform_int_distribution<int> bit(0, 7);
    for (int trial = 0; trial < 400; ++trial) {
      std::string bad = bytes;
      bad[where(rng)] ^= static_cast<char>(1 << bit(rng));
      absl::StatusOr<SphereHierarchy> parsed = SphereHierarchy::Deserialize(bad);
      if (!parsed.ok()) continue;
      ++accepted;
      // Whatever was accepted answers exactly.
      const RigidPose pose = RandomPose(rng, 3.0);
      absl::StatusOr<DistanceResult> fast = SeparationDistance(*parsed, {}, *hb, pose);
      absl::StatusOr<DistanceResult> slow =
          BruteForceSeparationDistance(parsed->spheres(), {}, other, pose);
      ASSERT_TRUE(fast.ok() && slow.ok());
      EXPECT_NEAR(fast->distance, slow->distance, 1e-9) << "trial " << trial;
    }
    EXPECT_LT(accepted, 400);
  }
}

}  // namespace
}  // namespace inscribe
