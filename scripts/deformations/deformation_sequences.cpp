#include "deformation_sequences.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace inscribe::sequences {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The box's axes ordered by extent: longest, middle, shortest.
std::array<int, 3> AxesByExtent(const BoundingBox& box) {
  std::array<int, 3> axes = {0, 1, 2};
  const Vector3 extent = box.extent();
  std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  return axes;
}

// Barr's bend (1984) in the plane of the longest and middle axes: the part of the model before
// the bend zone stays, the zone bends along circular arcs about a centre of curvature at
// distance R = W / angle from the middle of the box, and the part after it turns rigidly by
// the full angle. Lengths along the middle line are kept; the Jacobian determinant is
// (R - v) / R for v the offset from that line, so with R above half the box's middle extent
// nothing folds and the volume barely changes.
Vertices Bend(const Vertices& reference, const BoundingBox& box, double t) {
  const auto axes = AxesByExtent(box);
  const int a = axes[0], b = axes[1];
  const double length = box.extent()[a];
  const double full_angle = kPi / 3.0;
  // Wide enough that R >= 0.6 of the middle extent at the full angle.
  const double zone = std::max(0.25 * length, 0.6 * full_angle * box.extent()[b]);
  const double start = box.min[a] + std::max(0.0, 0.6 * length - 0.5 * zone);
  const double middle = 0.5 * (box.min[b] + box.max[b]);
  const double angle = t * full_angle;
  if (!(angle > 0.0)) return reference;
  const double radius = zone / angle;
  Vertices out = reference;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) {
    const double u = reference(i, a) - start;
    const double v = reference(i, b) - middle;
    if (u <= 0.0) continue;
    const double alpha = std::min(u, zone) / radius;
    const double beyond = std::max(0.0, u - zone);
    const double bent_u = (radius - v) * std::sin(alpha) + beyond * std::cos(alpha);
    const double bent_v = radius - (radius - v) * std::cos(alpha) + beyond * std::sin(alpha);
    out(i, a) = start + bent_u;
    out(i, b) = middle + bent_v;
  }
  return out;
}

Vertices Twist(const Vertices& reference, const BoundingBox& box, double t) {
  const auto [a, b, c] = AxesByExtent(box);
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double length = box.extent()[a];
  Vertices out = reference;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) {
    const double psi = t * 0.5 * kPi * (reference(i, a) - centre[a]) / length;
    const double y = reference(i, b) - centre[b];
    const double z = reference(i, c) - centre[c];
    out(i, b) = centre[b] + y * std::cos(psi) - z * std::sin(psi);
    out(i, c) = centre[c] + y * std::sin(psi) + z * std::cos(psi);
  }
  return out;
}

Vertices Rigid(const Vertices& reference, const BoundingBox& box, double t) {
  const Vector3 centre = 0.5 * (box.min + box.max);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(t * 0.5 * kPi, Vector3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Vector3 shift = t * 0.6 * box.diagonal() * Vector3(1.0, -0.5, 0.25).normalized();
  Vertices out(reference.rows(), 3);
  for (Eigen::Index i = 0; i < reference.rows(); ++i) {
    const Vector3 p = reference.row(i).transpose();
    out.row(i) = (rotation * (p - centre) + centre + shift).transpose();
  }
  return out;
}

// Radial map rho -> rho (1 - s w(rho / R)), w(x) = (1 - x^2)^2 on [0, 1): its derivative is
// 1 - s w + 4 s x^2 (1 - x^2) >= 1 - s > 0, so it is one-to-one.
Vertices Pinch(const Vertices& reference, const BoundingBox& box, double t) {
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double radius = 0.35 * box.extent().maxCoeff();
  const double strength = 0.45 * t;
  Vertices out = reference;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) {
    const Vector3 offset = reference.row(i).transpose() - centre;
    const double x = offset.norm() / radius;
    if (x >= 1.0) continue;
    const double w = (1.0 - x * x) * (1.0 - x * x);
    out.row(i) = (centre + offset * (1.0 - strength * w)).transpose();
  }
  return out;
}

}  // namespace

const char* DeformationKindName(DeformationKind kind) {
  switch (kind) {
    case DeformationKind::kBend:
      return "bend";
    case DeformationKind::kTwist:
      return "twist";
    case DeformationKind::kRigid:
      return "rigid";
    case DeformationKind::kPinch:
      return "pinch";
  }
  return "?";
}

std::vector<DeformationKind> AllDeformationKinds() {
  return {DeformationKind::kBend, DeformationKind::kTwist, DeformationKind::kRigid,
          DeformationKind::kPinch};
}

absl::StatusOr<DeformationKind> ParseDeformationKind(const std::string& name) {
  for (DeformationKind kind : AllDeformationKinds()) {
    if (name == DeformationKindName(kind)) return kind;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown deformation '", name, "' (bend, twist, rigid or pinch)"));
}

Vertices Deform(const Vertices& reference, DeformationKind kind, double t) {
  const BoundingBox box = ComputeBoundingBox(reference);
  switch (kind) {
    case DeformationKind::kBend:
      return Bend(reference, box, t);
    case DeformationKind::kTwist:
      return Twist(reference, box, t);
    case DeformationKind::kRigid:
      return Rigid(reference, box, t);
    case DeformationKind::kPinch:
      return Pinch(reference, box, t);
  }
  return reference;
}

std::vector<Vertices> DeformationSequence(const Vertices& reference, DeformationKind kind,
                                          int frames) {
  std::vector<Vertices> out;
  for (int k = 1; k <= frames; ++k) {
    out.push_back(Deform(reference, kind, static_cast<double>(k) / frames));
  }
  return out;
}

}  // namespace inscribe::sequences
