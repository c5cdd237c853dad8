// Certified separation distance: an interval that provably holds the exact distance between two
// solids, from each solid's internal sphere set (inside the solid) and certified cover (holding
// the solid, reaching at most delta outside it; cover_certificate.h).
//
// With A ⊆ solid_A ⊆ CA and CA within delta_A of solid_A (likewise for B):
//   lower = max(0, d(CA, CB))            the covers hold the solids, so these are no closer;
//   upper = max(0, min(d(A, B), max(0, d(CA, CB)) + delta_A + delta_B))
// where d is the sphere-union distance (negative when they overlap) and the exact distance is
// the solids' separation (0 when they touch or overlap). A and B are best the covers' cores
// (UpperBoundSpheres): balls inside the solid right under the cover's spheres, which bring
// upper within two spheres' protrusions of lower. The second term of upper: a point
// where the covers come closest (or overlap) is within delta_A of solid_A and delta_B of
// solid_B. Every sphere distance is computed exactly over all sphere pairs (no tolerance), and
// lower and upper are moved outward by a margin far above the rounding of the pose and of the
// few operations per pair (kCertifiedDistanceMargin times the pair's coordinate scale, plus
// kCertifiedDistanceFloor for lengths whose squares underflow).
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

// Margin on lower and upper: this fraction of the pair's coordinate scale (the largest
// |centre| + radius of either object's spheres, from the hierarchies' roots, plus the poses'
// translations), plus kCertifiedDistanceFloor.
inline constexpr double kCertifiedDistanceMargin = 1e-12;
// Absolute part of the margin, mesh units. Lengths below about 1e-154 have squares below the
// smallest normal double, whose square roots then err by up to about 1e-161 in absolute terms
// however small the coordinates; this stays far above that and far below any mesh's lengths.
inline constexpr double kCertifiedDistanceFloor = 1e-150;
// Largest coordinate scale (as above) a pair may have, mesh units: beyond it squared distances
// could overflow to infinity, which would make lower infinite for objects a finite distance
// apart. Such pairs are refused.
inline constexpr double kCertifiedDistanceMaxScale = 1e100;

// The spheres for CertifiedObject::internal: the cover's cores (CoverCores) when its
// certificate gives its per-sphere protrusions (CoverCertificate::protrusions) and some core
// is left, else the solid's internal set. The cores sit right under the cover's spheres, so
// they give an upper bound close to that of the internal set and the cores together, with
// half the spheres, and much tighter than the internal set's alone
// (docs/benchmarks/covers.md). INVALID_ARGUMENT for protrusions neither empty nor one
// finite value per cover sphere. O(N).
absl::StatusOr<std::vector<Sphere>> UpperBoundSpheres(const std::vector<Sphere>& internal,
                                                      const std::vector<Sphere>& cover,
                                                      const std::vector<double>& protrusions);

// One solid of a certified query. The hierarchies are not owned and must outlive the call.
struct CertifiedObject {
  const SphereHierarchy* internal = nullptr;  // spheres inside the solid (UpperBoundSpheres)
  const SphereHierarchy* cover = nullptr;     // spheres holding the whole solid (certified)
  double cover_delta = 0.0;                   // the cover's certified protrusion bound, >= 0
};

// OK, or INVALID_ARGUMENT naming the problem: a missing hierarchy, a delta that is negative or
// not finite. O(1).
absl::Status CheckCertifiedObject(const CertifiedObject& object);

// "Are the solids closer than d?" answered without a wrong yes or no.
enum class CloserAnswer { kYes, kNo, kUndecided };

// "yes", "no", "undecided".
const char* CloserAnswerName(CloserAnswer answer);

// The answer the interval gives: yes when upper < d, no when lower >= d, else undecided.
CloserAnswer DecideCloser(double lower, double upper, double closer_than);

struct CertifiedDistanceResult {
  // lower <= exact distance <= upper, 0 <= lower <= upper (mesh units).
  double lower = 0.0;
  double upper = std::numeric_limits<double>::infinity();
  // DecideCloser(lower, upper, closer_than); kUndecided when no closer_than was asked.
  CloserAnswer closer = CloserAnswer::kUndecided;
  // The two sphere queries behind it: internal sets (upper) and covers (lower).
  DistanceResult internal, cover;
};

// One posed pair: two objects (not owned) and their world poses.
struct CertifiedPair {
  const CertifiedObject* a = nullptr;
  const CertifiedObject* b = nullptr;
  RigidPose pose_a, pose_b;
};

// The margin on a posed pair's bounds (kCertifiedDistanceMargin times its coordinate scale,
// plus kCertifiedDistanceFloor), for poses already normalised. INVALID_ARGUMENT for a scale
// above kCertifiedDistanceMaxScale. O(1).
absl::StatusOr<double> CertifiedDistanceMargin(const CertifiedObject& a, const RigidPose& pose_a,
                                               const CertifiedObject& b, const RigidPose& pose_b);

// The interval from the two exact sphere queries of a pair: `cover` between the covers,
// `internal` between the internal sets (it may have been limited to max_distance =
// max(0, cover distance) + the two deltas: a distance of +infinity then means "no closer",
// which gives the same upper bound). `deltas` is the sum of the covers' deltas, `margin`
// CertifiedDistanceMargin's. O(1).
CertifiedDistanceResult CertifiedInterval(DistanceResult internal, DistanceResult cover,
                                          double deltas, double margin, double closer_than);

// The interval for every pair (entry i answers pairs[i]), and the closer-than answer when
// closer_than is finite. Poses are normalised first (NormalizedPose): the exact distance is
// that of the solids under the rotation of the unit quaternion. Parallel (TBB) like
// PairSeparationDistances, cancellable through `cancel` (CANCELLED). Errors: INVALID_ARGUMENT
// naming "pairs[i]" for a missing object, a bad object (CheckCertifiedObject), a bad pose or a
// coordinate scale above kCertifiedDistanceMaxScale; for a closer_than that is NaN.
absl::StatusOr<std::vector<CertifiedDistanceResult>> CertifiedDistances(
    const std::vector<CertifiedPair>& pairs,
    double closer_than = std::numeric_limits<double>::infinity(),
    const std::atomic<bool>* cancel = nullptr);

}  // namespace inscribe
