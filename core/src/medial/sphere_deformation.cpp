#include "inscribe/medial/sphere_deformation.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "inscribe/balls/union_of_balls.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Halvings allowed per sphere. Each one at least halves r - max(d, 0) <= 2r, so r / xi below
// 2^200 needs fewer; the cap only guards against NaN-free but absurd scales.
constexpr int kMaxShrinkSteps = 200;

// An orthonormal frame at a contact point: columns tangent, bitangent, inner normal.
using Frame = Eigen::Matrix3d;

struct ContactPoint {
  Vector3 point;
  Frame frame;
};

// The contact point and its frame on `mesh` with vertex pseudonormals `vertex_normals`: the
// inner normal is minus the barycentric blend of the unit vertex normals (the face normal where
// that blend vanishes), the tangent the triangle's first usable edge projected on the tangent
// plane.
ContactPoint ContactFrame(const Mesh& mesh, const std::vector<Vector3>& vertex_normals,
                          const std::vector<Vector3>& face_normals, const SurfaceContact& contact) {
  const std::int32_t t = contact.triangle;
  Vector3 corners[3];
  Vector3 normal = Vector3::Zero();
  for (int k = 0; k < 3; ++k) {
    const auto v = mesh.triangles(t, k);
    corners[k] = mesh.vertices.row(v).transpose();
    const Vector3& n = vertex_normals[static_cast<std::size_t>(v)];
    const double length = n.norm();
    if (length > 0.0) normal += contact.barycentric[k] * (n / length);
  }
  ContactPoint out;
  out.point = contact.barycentric[0] * corners[0] + contact.barycentric[1] * corners[1] +
              contact.barycentric[2] * corners[2];
  double length = normal.norm();
  if (!(length > 1e-12)) {
    normal = face_normals[static_cast<std::size_t>(t)];
    length = normal.norm();
  }
  // A contact on no usable normal at all (every corner's triangles degenerate): any axis.
  const Vector3 inner = length > 0.0 ? Vector3(-normal / length) : Vector3::UnitZ();
  Vector3 tangent = Vector3::Zero();
  for (int k = 0; k < 3 && !(tangent.norm() > 1e-12); ++k) {
    const Vector3 edge = corners[(k + 1) % 3] - corners[k];
    tangent = edge - edge.dot(inner) * inner;
    const double edge_length = edge.norm();
    if (edge_length > 0.0) tangent /= edge_length;
  }
  if (!(tangent.norm() > 1e-12)) tangent = inner.unitOrthogonal();
  tangent.normalize();
  out.frame.col(0) = tangent;
  out.frame.col(1) = inner.cross(tangent);
  out.frame.col(2) = inner;
  return out;
}

// Inner depth: the distance from `query` to the boundary, positive inside, negative outside,
// 0 on it. `bound`: the distance to some boundary point.
struct Depth {
  double depth;
  BoundaryPoint closest;
};

Depth DepthOf(const BoundaryOracle& oracle, const Vector3& query, double bound) {
  Depth out;
  out.closest = oracle.ClosestPoint(query, BoundaryOracle::PaddedDistanceBound(bound));
  const Side side = oracle.Classify(query, out.closest);
  out.depth = side == Side::kInside    ? out.closest.distance
              : side == Side::kOutside ? -out.closest.distance
                                       : 0.0;
  return out;
}

double LargestExtent(const Mesh& mesh) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  return box.extent().maxCoeff();
}

// Signed volume of `triangles` on `vertices`, without building a Mesh.
double EnclosedVolume(const Triangles& triangles, const Vertices& vertices) {
  double six_volume = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Vector3 a = vertices.row(triangles(t, 0)).transpose();
    const Vector3 b = vertices.row(triangles(t, 1)).transpose();
    const Vector3 c = vertices.row(triangles(t, 2)).transpose();
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

absl::Status CheckReferenceSphere(const SphereSet& set, std::size_t i,
                                  const Vector3& contact_point) {
  const Sphere& s = set.spheres[i];
  const SurfaceContact& contact = set.contacts[i];
  const std::string what = absl::StrCat("reference sphere ", i, ": ");
  if (absl::Status valid = CheckSphere(s, i); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("reference ", valid.message()));
  }
  const double offset = (s.center - contact_point).norm();
  if (!(std::abs(offset - s.radius) <= 1e-6 * s.radius)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, "its contact (triangle ", contact.triangle, ") is ", offset,
                     " from its centre but its radius is ", s.radius,
                     ": a reference sphere must touch the boundary at its contact"));
  }
  return absl::OkStatus();
}

absl::Status CheckContact(const Mesh& mesh, const SurfaceContact& contact, std::size_t i) {
  const std::string what = absl::StrCat("reference sphere ", i, ": ");
  if (contact.triangle < 0 || contact.triangle >= mesh.num_triangles()) {
    return absl::InvalidArgumentError(absl::StrCat(what, "contact triangle ", contact.triangle,
                                                   " is not one of the mesh's ",
                                                   mesh.num_triangles(), " triangles"));
  }
  const Vector3& w = contact.barycentric;
  if (!w.allFinite() || w.minCoeff() < -1e-9 || std::abs(w.sum() - 1.0) > 1e-9) {
    return absl::InvalidArgumentError(absl::StrCat(what, "contact barycentrics (", w[0], ", ", w[1],
                                                   ", ", w[2],
                                                   ") must be finite, non-negative and sum to 1"));
  }
  return absl::OkStatus();
}

}  // namespace

struct SphereDeformer::Impl {
  Mesh reference;
  SphereSet spheres;
  // Per sphere: the reference direction (c - A) / |c - A| in the reference contact frame.
  std::vector<Vector3> local_direction;
  DeformationOptions options;
  BoundaryOracle oracle;

  Impl(Mesh mesh, SphereSet set, const DeformationOptions& opts, BoundaryOracle built)
      : reference(std::move(mesh)),
        spheres(std::move(set)),
        options(opts),
        oracle(std::move(built)) {}
};

absl::Status CheckDeformationOptions(const DeformationOptions& options) {
  if (!std::isfinite(options.xi) || options.xi < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("xi must be finite and >= 0 (0 = the default), got ", options.xi));
  }
  return absl::OkStatus();
}

absl::StatusOr<SphereDeformer> SphereDeformer::Create(Mesh reference, SphereSet spheres,
                                                      const DeformationOptions& options) {
  if (absl::Status s = CheckDeformationOptions(options); !s.ok()) return s;
  if (spheres.contacts.size() != spheres.spheres.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the reference spheres need one contact each to be moved (", spheres.spheres.size(),
        " spheres, ", spheres.contacts.size(), " contacts); inscribe generate writes them"));
  }
  if (spheres.spheres.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return absl::InvalidArgumentError("more than 2^31 - 1 reference spheres");
  }
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    if (absl::Status s = CheckContact(reference, spheres.contacts[i], i); !s.ok()) return s;
  }
  if (!(EnclosedVolume(reference.triangles, reference.vertices) > 0.0)) {
    return absl::InvalidArgumentError(
        "the reference mesh encloses no positive volume (open, inverted or flat)");
  }
  BoundaryOracleOptions oracle_options;
  oracle_options.inside_test = InsideTest::kExactWinding;
  oracle_options.backend = options.backend;
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(reference, oracle_options);
  if (!oracle.ok()) return oracle.status();

  DeformationOptions resolved = options;
  if (resolved.xi == 0.0) resolved.xi = 0.0025 * LargestExtent(reference);
  auto impl = std::make_unique<Impl>(std::move(reference), std::move(spheres), resolved,
                                     *std::move(oracle));
  impl->local_direction.resize(impl->spheres.size());
  for (std::size_t i = 0; i < impl->spheres.size(); ++i) {
    const ContactPoint at = ContactFrame(impl->reference, impl->oracle.vertex_normals(),
                                         impl->oracle.face_normals(), impl->spheres.contacts[i]);
    if (absl::Status s = CheckReferenceSphere(impl->spheres, i, at.point); !s.ok()) {
      return s;
    }
    const Vector3 direction = (impl->spheres.spheres[i].center - at.point).normalized();
    impl->local_direction[i] = at.frame.transpose() * direction;
  }
  return SphereDeformer(std::move(impl));
}

SphereDeformer::SphereDeformer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SphereDeformer::SphereDeformer(SphereDeformer&&) noexcept = default;
SphereDeformer& SphereDeformer::operator=(SphereDeformer&&) noexcept = default;
SphereDeformer::~SphereDeformer() = default;

const BoundaryOracle& SphereDeformer::oracle() const { return impl_->oracle; }
const DeformationOptions& SphereDeformer::options() const { return impl_->options; }
const SphereSet& SphereDeformer::reference_spheres() const { return impl_->spheres; }

absl::StatusOr<DeformedSpheres> SphereDeformer::Update(const Vertices& deformed_vertices) {
  const auto start = Clock::now();
  const Impl& ref = *impl_;
  if (deformed_vertices.rows() != ref.reference.num_vertices()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the deformed mesh has ", deformed_vertices.rows(),
                     " vertices; the reference has ", ref.reference.num_vertices()));
  }
  if (!deformed_vertices.allFinite()) {
    for (Eigen::Index v = 0; v < deformed_vertices.rows(); ++v) {
      if (!deformed_vertices.row(v).allFinite()) {
        return absl::InvalidArgumentError(
            absl::StrCat("deformed vertex ", v, " has a non-finite coordinate"));
      }
    }
  }
  const double volume = EnclosedVolume(ref.reference.triangles, deformed_vertices);
  if (!(volume > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the reference's triangles on the deformed vertices enclose volume ", volume,
                     ", not a positive one: the deformation inverts or flattens the solid"));
  }
  if (absl::Status s = impl_->oracle.Refit(deformed_vertices); !s.ok()) return s;

  const BoundaryOracle& oracle = impl_->oracle;
  const Mesh& mesh = oracle.mesh();
  const DeformationOptions& options = ref.options;
  const double xi = options.xi;
  const std::size_t n = ref.spheres.size();

  struct Moved {
    Sphere sphere;
    SurfaceContact contact;
    double protrusion = 0.0;
    int steps = 0;
    std::int64_t queries = 0;
    bool dropped = false;
  };
  std::vector<Moved> moved(n);
  internal::ParallelFor(std::size_t{0}, n, [&](std::size_t i) {
    const SurfaceContact& contact = ref.spheres.contacts[i];
    const ContactPoint at =
        ContactFrame(mesh, oracle.vertex_normals(), oracle.face_normals(), contact);
    const Vector3 direction = options.direction == ContactDirection::kCarriedFrame
                                  ? Vector3(at.frame * ref.local_direction[i])
                                  : Vector3(at.frame.col(2));
    const Vector3& p = at.point;
    Moved& out = moved[i];
    // Algorithm 1 (Shrink), with the centre's depth signed: a centre pushed outside by a bad
    // normal estimate halves r towards 0 instead of (r + d) / 2 going negative.
    double r = ref.spheres.spheres[i].radius;
    Vector3 c = p + r * direction;
    Depth d = DepthOf(oracle, c, r);
    ++out.queries;
    while (r - d.depth >= xi && out.steps < kMaxShrinkSteps) {
      r = 0.5 * (r + std::max(d.depth, 0.0));
      c = p + r * direction;
      d = DepthOf(oracle, c, r);
      ++out.queries;
      ++out.steps;
    }
    if (options.strict) {
      // Return (c, d): the centre must be inside for that to be an internal sphere.
      while (!(d.depth > 0.0) && out.steps < kMaxShrinkSteps) {
        r *= 0.5;
        c = p + r * direction;
        d = DepthOf(oracle, c, r);
        ++out.queries;
        ++out.steps;
      }
      if (!(d.depth > 0.0)) {
        out.dropped = true;
        return;
      }
      out.sphere = Sphere{c, d.depth};
      out.contact = SurfaceContact{d.closest.triangle, d.closest.barycentric};
      out.protrusion = 0.0;
    } else {
      out.sphere = Sphere{c, r};
      out.contact = contact;
      out.protrusion = r - d.depth;
    }
  });

  DeformedSpheres result;
  result.xi = xi;
  result.max_protrusion = -std::numeric_limits<double>::infinity();
  result.set.spheres.reserve(n);
  result.set.contacts.reserve(n);
  result.reference_index.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Moved& m = moved[i];
    result.closest_point_queries += m.queries;
    result.max_shrink_steps = std::max(result.max_shrink_steps, m.steps);
    if (m.dropped) {
      ++result.dropped;
      continue;
    }
    if (m.steps > 0) ++result.shrunk;
    result.max_protrusion = std::max(result.max_protrusion, m.protrusion);
    result.set.spheres.push_back(m.sphere);
    result.set.contacts.push_back(m.contact);
    result.reference_index.push_back(static_cast<std::int32_t>(i));
  }
  if (result.set.spheres.empty()) result.max_protrusion = 0.0;
  result.seconds = SecondsSince(start);
  return result;
}

absl::StatusOr<DeformationErrorBounds> BoundDeformationError(const BoundaryOracle& oracle,
                                                             const std::vector<Sphere>& spheres,
                                                             double xi) {
  const auto start = Clock::now();
  if (!std::isfinite(xi) || xi < 0.0) {
    return absl::InvalidArgumentError(absl::StrCat("xi must be finite and >= 0, got ", xi));
  }
  if (absl::Status valid = CheckSpheres(spheres); !valid.ok()) return valid;
  DeformationErrorBounds out;
  out.volume_mesh = SignedVolume(oracle.mesh());
  if (!(out.volume_mesh > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the mesh encloses volume ", out.volume_mesh, ", not a positive one"));
  }
  // Depth of every centre (positive inside).
  std::vector<double> depth(spheres.size());
  internal::ParallelFor(std::size_t{0}, spheres.size(), [&](std::size_t i) {
    const BoundaryPoint closest = oracle.ClosestPoint(spheres[i].center);
    const Side side = oracle.Classify(spheres[i].center, closest);
    depth[i] = side == Side::kInside    ? closest.distance
               : side == Side::kOutside ? -closest.distance
                                        : 0.0;
  });
  std::vector<Sphere> all, shrunk, inner;
  all.reserve(spheres.size());
  bool internal = true;
  double max_protrusion = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Sphere& s = spheres[i];
    if (s.radius > 0.0) all.push_back(s);
    if (s.radius > xi) shrunk.push_back(Sphere{s.center, s.radius - xi});
    const double r_in = std::min(s.radius, depth[i]);
    if (r_in > 0.0) inner.push_back(Sphere{s.center, r_in});
    if (depth[i] < s.radius) internal = false;
    max_protrusion = std::max(max_protrusion, s.radius - depth[i]);
  }
  for (auto [balls, volume] :
       {std::pair{&all, &out.volume_union}, std::pair{&shrunk, &out.volume_union_shrunk},
        std::pair{&inner, &out.volume_union_inner}}) {
    if (balls->empty()) {
      *volume = 0.0;
      continue;
    }
    absl::StatusOr<double> v = UnionVolume(*balls);
    if (!v.ok()) return v.status();
    *volume = *v;
  }
  const double vm = out.volume_mesh;
  const double vu = out.volume_union;
  out.exact = internal;
  out.nerr_lower = std::abs(vu - vm) / vm;
  // When every sphere is internal U_in = U and the bound collapses to Lemma 1's exact value;
  // use the same expression so that lower == upper to the last bit.
  out.nerr_upper = internal ? out.nerr_lower : (vm - vu + 2.0 * (vu - out.volume_union_inner)) / vm;
  out.nerr_upper = std::max(out.nerr_upper, out.nerr_lower);
  out.uniform_xi_holds = spheres.empty() || max_protrusion < xi;
  out.nerr_upper_uniform_xi = out.uniform_xi_holds
                                  ? (vm - vu + 2.0 * (vu - out.volume_union_shrunk)) / vm
                                  : std::numeric_limits<double>::infinity();
  out.seconds = SecondsSince(start);
  return out;
}

}  // namespace inscribe
