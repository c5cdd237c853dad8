#include "inscribe/distance/certified_distance.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/cover/cover_certificate.h"

namespace inscribe {
namespace {

// max over the hierarchy's spheres of |centre| + radius, bounded by the sphere around the root.
double LocalExtent(const SphereHierarchy& h) {
  const HierarchyRef root = h.root();
  const Sphere& s =
      IsLeaf(root) ? h.spheres()[static_cast<std::size_t>(LeafSphere(root))] : h.outer_sphere(root);
  return s.center.norm() + s.radius;
}

double Extent(const CertifiedObject& object) {
  return std::max(LocalExtent(*object.internal), LocalExtent(*object.cover));
}

absl::Status PairError(std::size_t index, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("pairs[", index, "]: ", status.message()));
}

}  // namespace

absl::StatusOr<std::vector<Sphere>> UpperBoundSpheres(const std::vector<Sphere>& internal,
                                                      const std::vector<Sphere>& cover,
                                                      const std::vector<double>& protrusions) {
  if (protrusions.empty()) return internal;
  absl::StatusOr<std::vector<Sphere>> cores = CoverCores(cover, protrusions);
  if (!cores.ok()) return cores.status();
  if (cores->empty()) return internal;
  return cores;
}

absl::Status CheckCertifiedObject(const CertifiedObject& object) {
  if (object.internal == nullptr) {
    return absl::InvalidArgumentError("the internal sphere hierarchy is missing");
  }
  if (object.cover == nullptr) return absl::InvalidArgumentError("the cover hierarchy is missing");
  if (!std::isfinite(object.cover_delta) || object.cover_delta < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover delta ", object.cover_delta, " is not a finite number >= 0"));
  }
  return absl::OkStatus();
}

const char* CloserAnswerName(CloserAnswer answer) {
  switch (answer) {
    case CloserAnswer::kYes:
      return "yes";
    case CloserAnswer::kNo:
      return "no";
    case CloserAnswer::kUndecided:
      break;
  }
  return "undecided";
}

CloserAnswer DecideCloser(double lower, double upper, double closer_than) {
  if (upper < closer_than) return CloserAnswer::kYes;
  if (lower >= closer_than) return CloserAnswer::kNo;
  return CloserAnswer::kUndecided;
}

absl::StatusOr<double> CertifiedDistanceMargin(const CertifiedObject& a, const RigidPose& pose_a,
                                               const CertifiedObject& b, const RigidPose& pose_b) {
  const double scale =
      Extent(a) + Extent(b) + pose_a.translation.norm() + pose_b.translation.norm();
  if (!(scale <= kCertifiedDistanceMaxScale)) {
    return absl::InvalidArgumentError(
        absl::StrCat("coordinates reach ", scale, " mesh units, beyond the ",
                     kCertifiedDistanceMaxScale, " that certified distances support"));
  }
  return kCertifiedDistanceMargin * scale + kCertifiedDistanceFloor;
}

CertifiedDistanceResult CertifiedInterval(DistanceResult internal, DistanceResult cover,
                                          double deltas, double margin, double closer_than) {
  CertifiedDistanceResult r;
  const double covers = cover.distance;
  r.lower = std::max(0.0, covers - margin);
  r.upper = std::max(0.0, std::min(internal.distance, std::max(0.0, covers) + deltas) + margin);
  // Covers that are no closer than the internal sets, less the margins, can only come from
  // sets that are not what they claim: keep the interval ordered regardless.
  r.upper = std::max(r.upper, r.lower);
  r.closer = std::isfinite(closer_than) ? DecideCloser(r.lower, r.upper, closer_than)
                                        : CloserAnswer::kUndecided;
  r.internal = std::move(internal);
  r.cover = std::move(cover);
  return r;
}

absl::StatusOr<std::vector<CertifiedDistanceResult>> CertifiedDistances(
    const std::vector<CertifiedPair>& pairs, double closer_than, const std::atomic<bool>* cancel) {
  if (std::isnan(closer_than)) return absl::InvalidArgumentError("closer_than is NaN");
  std::vector<PosedPair> internal(pairs.size()), cover(pairs.size());
  std::vector<double> margin(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const CertifiedPair& p = pairs[i];
    if (p.a == nullptr || p.b == nullptr) {
      return PairError(i, absl::InvalidArgumentError("an object is missing"));
    }
    for (const CertifiedObject* object : {p.a, p.b}) {
      if (absl::Status s = CheckCertifiedObject(*object); !s.ok()) return PairError(i, s);
    }
    absl::StatusOr<RigidPose> pose_a = NormalizedPose(p.pose_a);
    if (!pose_a.ok()) return PairError(i, pose_a.status());
    absl::StatusOr<RigidPose> pose_b = NormalizedPose(p.pose_b);
    if (!pose_b.ok()) return PairError(i, pose_b.status());
    internal[i] = PosedPair{p.a->internal, p.b->internal, *pose_a, *pose_b};
    cover[i] = PosedPair{p.a->cover, p.b->cover, *pose_a, *pose_b};
    absl::StatusOr<double> m = CertifiedDistanceMargin(*p.a, *pose_a, *p.b, *pose_b);
    if (!m.ok()) return PairError(i, m.status());
    margin[i] = *m;
  }
  // Exact sphere distances (no tolerance): a bound that stopped early would not be sound.
  absl::StatusOr<std::vector<DistanceResult>> inner = PairSeparationDistances(internal, {}, cancel);
  if (!inner.ok()) return inner.status();
  absl::StatusOr<std::vector<DistanceResult>> outer = PairSeparationDistances(cover, {}, cancel);
  if (!outer.ok()) return outer.status();

  std::vector<CertifiedDistanceResult> out;
  out.reserve(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    out.push_back(CertifiedInterval(std::move((*inner)[i]), std::move((*outer)[i]),
                                    pairs[i].a->cover_delta + pairs[i].b->cover_delta, margin[i],
                                    closer_than));
  }
  return out;
}

}  // namespace inscribe
