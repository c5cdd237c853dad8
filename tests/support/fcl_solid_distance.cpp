#include "support/fcl_solid_distance.h"

#include <numeric>

namespace inscribe::testing {
namespace {

// Union-find root with path halving.
Eigen::Index Root(std::vector<Eigen::Index>& parent, Eigen::Index i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

// Whether a shell of `inner` (one vertex each) lies inside `outer`'s solid.
bool ShellInside(const FclSolid& inner, const RigidPose& pose_inner, const FclSolid& outer,
                 const RigidPose& pose_outer) {
  const RigidPose into = pose_outer.Inverse() * pose_inner;
  for (const Eigen::Index v : inner.shell_vertices) {
    const Vector3 p = into * Vector3(inner.solid->mesh().vertices.row(v).transpose());
    if (outer.solid->oracle.Classify(p) != Side::kOutside) return true;
  }
  return false;
}

}  // namespace

std::shared_ptr<FclMesh> BuildFclMesh(const Mesh& mesh) {
  std::vector<fcl::Vector3d> points(static_cast<std::size_t>(mesh.num_vertices()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i] = mesh.vertices.row(static_cast<Eigen::Index>(i)).transpose();
  }
  std::vector<fcl::Triangle> triangles(static_cast<std::size_t>(mesh.num_triangles()));
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto t = mesh.triangles.row(static_cast<Eigen::Index>(i));
    triangles[i] = fcl::Triangle(static_cast<std::size_t>(t(0)), static_cast<std::size_t>(t(1)),
                                 static_cast<std::size_t>(t(2)));
  }
  auto model = std::make_shared<FclMesh>();
  model->beginModel();
  model->addSubModel(points, triangles);
  model->endModel();
  return model;
}

fcl::Transform3d ToFcl(const RigidPose& pose) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = pose.rotation.normalized().toRotationMatrix();
  t.translation() = pose.translation;
  return t;
}

FclSolid MakeFclSolid(const Solid& solid) {
  const Mesh& mesh = solid.mesh();
  std::vector<Eigen::Index> parent(static_cast<std::size_t>(mesh.num_vertices()));
  std::iota(parent.begin(), parent.end(), Eigen::Index{0});
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 1; k < 3; ++k) {
      parent[static_cast<std::size_t>(Root(parent, mesh.triangles(t, k)))] =
          Root(parent, mesh.triangles(t, 0));
    }
  }
  FclSolid out{&solid, BuildFclMesh(mesh), {}};
  std::vector<bool> seen(parent.size(), false);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Eigen::Index v = mesh.triangles(t, 0);
    const auto root = static_cast<std::size_t>(Root(parent, v));
    if (!seen[root]) {
      seen[root] = true;
      out.shell_vertices.push_back(v);
    }
  }
  return out;
}

bool SurfacesCollide(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                     const RigidPose& pose_b) {
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide(a.fcl.get(), ToFcl(pose_a), b.fcl.get(), ToFcl(pose_b), request, result);
  return result.isCollision();
}

double SurfaceDistance(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                       const RigidPose& pose_b) {
  const fcl::DistanceRequestd request;  // rel_err = abs_err = 0: the exact minimum
  fcl::DistanceResultd result;          // fresh: a reused result keeps its earlier minimum
  fcl::distance(a.fcl.get(), ToFcl(pose_a), b.fcl.get(), ToFcl(pose_b), request, result);
  return result.min_distance;
}

ExactSolidDistance SolidDistance(const FclSolid& a, const RigidPose& pose_a, const FclSolid& b,
                                 const RigidPose& pose_b) {
  if (SurfacesCollide(a, pose_a, b, pose_b)) return {0.0, SolidContact::kSurfaces};
  if (ShellInside(a, pose_a, b, pose_b) || ShellInside(b, pose_b, a, pose_a)) {
    return {0.0, SolidContact::kContained};
  }
  return {SurfaceDistance(a, pose_a, b, pose_b), SolidContact::kApart};
}

}  // namespace inscribe::testing
