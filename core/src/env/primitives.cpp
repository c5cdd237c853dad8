#include "inscribe/env/primitives.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/distance/certified_distance.h"

namespace inscribe {

const char* PrimitiveShapeName(PrimitiveShape shape) {
  switch (shape) {
    case PrimitiveShape::kBox:
      return "box";
    case PrimitiveShape::kSphere:
      return "sphere";
    case PrimitiveShape::kCapsule:
      return "capsule";
    case PrimitiveShape::kCylinder:
      return "cylinder";
    case PrimitiveShape::kPlane:
      return "plane";
  }
  return "?";
}

double PrimitiveSignedDistance(const Primitive& primitive, const Vector3& point) {
  const Vector3 x = primitive.pose.Inverse() * point;
  switch (primitive.shape) {
    case PrimitiveShape::kBox: {
      const Vector3 q = x.cwiseAbs() - primitive.half_extents;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case PrimitiveShape::kSphere:
      return x.norm() - primitive.radius;
    case PrimitiveShape::kCapsule: {
      const double z = std::clamp(x.z(), -primitive.half_length, primitive.half_length);
      return Vector3(x.x(), x.y(), x.z() - z).norm() - primitive.radius;
    }
    case PrimitiveShape::kCylinder: {
      const double a = std::hypot(x.x(), x.y()) - primitive.radius;
      const double b = std::abs(x.z()) - primitive.half_length;
      return std::hypot(std::max(a, 0.0), std::max(b, 0.0)) + std::min(std::max(a, b), 0.0);
    }
    case PrimitiveShape::kPlane:
      return x.z();
  }
  return std::numeric_limits<double>::quiet_NaN();
}

absl::StatusOr<PrimitiveEnvironment> PrimitiveEnvironment::Create(
    std::vector<Primitive> primitives) {
  double scale = 0.0;
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    Primitive& p = primitives[i];
    const std::string name = absl::StrCat("primitive ", i, " (", PrimitiveShapeName(p.shape), ")");
    absl::StatusOr<RigidPose> pose = NormalizedPose(p.pose);
    if (!pose.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": pose: ", pose.status().message()));
    }
    p.pose = *pose;
    auto positive = [&](double value, const char* field) -> absl::Status {
      if (std::isfinite(value) && value > 0.0) return absl::OkStatus();
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": ", field, " ", value, " must be finite and > 0 (metres)"));
    };
    absl::Status status;
    double size = 0.0;
    switch (p.shape) {
      case PrimitiveShape::kBox:
        for (int axis = 0; axis < 3 && status.ok(); ++axis) {
          status = positive(p.half_extents[axis], "half_extents");
        }
        size = p.half_extents.norm();
        break;
      case PrimitiveShape::kSphere:
        status = positive(p.radius, "radius");
        size = p.radius;
        break;
      case PrimitiveShape::kCapsule:
        status = positive(p.radius, "radius");
        if (status.ok() && !(std::isfinite(p.half_length) && p.half_length >= 0.0)) {
          status = absl::InvalidArgumentError(
              absl::StrCat(name, ": half_length ", p.half_length, " must be finite and >= 0"));
        }
        size = p.radius + p.half_length;
        break;
      case PrimitiveShape::kCylinder:
        status = positive(p.radius, "radius");
        if (status.ok()) status = positive(p.half_length, "half_length");
        size = p.radius + p.half_length;
        break;
      case PrimitiveShape::kPlane:
        break;
    }
    if (!status.ok()) return status;
    scale = std::max(scale, p.pose.translation.norm() + size);
  }
  return PrimitiveEnvironment(std::move(primitives), scale);
}

ClearanceInterval PrimitiveEnvironment::Bounds(const Sphere& ball) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Primitive& p : primitives_)
    best = std::min(best, PrimitiveSignedDistance(p, ball.center));
  const double margin =
      kEnvironmentMargin * (scale_ + ball.center.cwiseAbs().maxCoeff() + ball.radius) +
      kCertifiedDistanceFloor;
  return {best - ball.radius - margin, best - ball.radius + margin};
}

int PrimitiveEnvironment::FirstColliding(absl::Span<const Sphere> balls) const {
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (!Bounds(balls[i]).clear()) return static_cast<int>(i);
  }
  return -1;
}

void PrimitiveEnvironment::Clearances(absl::Span<const Sphere> balls, const ClearanceRequest&,
                                      absl::Span<ClearanceInterval> out) const {
  assert(out.size() == balls.size());
  for (std::size_t i = 0; i < balls.size(); ++i) out[i] = Bounds(balls[i]);
}

}  // namespace inscribe
