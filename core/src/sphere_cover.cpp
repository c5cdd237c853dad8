#include "inscribe/sphere_cover.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "cover_cells.h"
#include "inscribe/sphere_set_generation.h"
#include "surface_sampling.h"

namespace inscribe {
namespace {

// A sphere grown to reach a point or a cell's corner reaches this much farther (relative),
// far above rounding, so the certificate's own margin (1e-12 on squares) is met.
constexpr double kReachMargin = 1e-9;
// Fixed, so that covers are reproducible.
constexpr std::uint64_t kGrowthSeed = 0x636f766572;  // "cover"
constexpr int kMaxRounds = 8;

// The sphere needing the least growth to reach `p`, and the radius it needs; radius 0 when
// some sphere already holds p.
std::pair<std::size_t, double> NearestReach(const std::vector<Sphere>& spheres, const Vector3& p) {
  std::size_t best = 0;
  double best_gap = std::numeric_limits<double>::infinity(), best_distance = 0.0;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const double distance = (p - spheres[i].center).norm();
    const double gap = distance - spheres[i].radius;
    if (gap < best_gap) {
      best_gap = gap;
      best = i;
      best_distance = distance;
    }
  }
  if (best_gap < 0.0) return {best, 0.0};
  return {best, best_distance * (1.0 + kReachMargin)};
}

// Grows spheres so that every point (rows of `points`) lies in one: each point goes to the
// sphere that needs the least growth, judged on the radii before any growth. Parallel and
// deterministic (per-sphere maxima).
void GrowToReach(const Vertices& points, std::vector<Sphere>* spheres) {
  const std::vector<Sphere>& before = *spheres;
  tbb::combinable<std::vector<double>> needs(
      [&before] { return std::vector<double>(before.size(), 0.0); });
  tbb::parallel_for(Eigen::Index{0}, points.rows(), [&](Eigen::Index row) {
    const auto [sphere, radius] = NearestReach(before, points.row(row).transpose());
    if (radius > 0.0) {
      double& need = needs.local()[sphere];
      need = std::max(need, radius);
    }
  });
  std::vector<double> need(before.size(), 0.0);
  needs.combine_each([&need](const std::vector<double>& local) {
    for (std::size_t i = 0; i < need.size(); ++i) need[i] = std::max(need[i], local[i]);
  });
  for (std::size_t i = 0; i < need.size(); ++i) {
    (*spheres)[i].radius = std::max((*spheres)[i].radius, need[i]);
  }
}

// Grows, for each cell in order, the sphere that needs the least growth to contain it (its
// farthest corner).
void GrowToContain(const std::vector<CoverCell>& cells, std::vector<Sphere>* spheres) {
  for (const CoverCell& cell : cells) {
    std::size_t best = 0;
    double best_growth = std::numeric_limits<double>::infinity(), best_reach = 0.0;
    const Vector3 hi = cell.min + Vector3::Constant(cell.side);  // exact: dyadic cells
    for (std::size_t i = 0; i < spheres->size(); ++i) {
      const Sphere& s = (*spheres)[i];
      const double reach = std::sqrt(internal::FarthestCornerSquared(s.center, cell.min, hi));
      if (reach - s.radius < best_growth) {
        best_growth = reach - s.radius;
        best = i;
        best_reach = reach;
      }
    }
    Sphere& grown = (*spheres)[best];
    grown.radius = std::max(grown.radius, best_reach * (1.0 + kReachMargin));
  }
}

// Every mesh vertex, then `count` boundary samples.
Vertices GrowthPoints(const Mesh& mesh, std::int64_t count) {
  const Vertices samples = internal::SampleBoundaryByArea(mesh, count, kGrowthSeed);
  Vertices points(mesh.vertices.rows() + samples.rows(), 3);
  points << mesh.vertices, samples;
  return points;
}

}  // namespace

absl::Status CheckCoverParameters(const CoverParameters& p) {
  if (p.max_spheres && *p.max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: max_spheres must be positive, got ", *p.max_spheres));
  }
  if (p.max_spheres && p.max_protrusion) {
    return absl::InvalidArgumentError(
        "cover: give max_spheres or max_protrusion, not both (a budget, or a delta to reach)");
  }
  if (p.max_protrusion && !(std::isfinite(*p.max_protrusion) && *p.max_protrusion > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: max_protrusion must be a finite length > 0, got ", *p.max_protrusion));
  }
  if (p.growth_samples < 0 || p.growth_samples > 100'000'000) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: growth_samples must lie in 0..100,000,000, got ", p.growth_samples));
  }
  if (absl::Status s = CheckCoverCertifyOptions(p.certify); !s.ok()) return s;
  return CheckMedialSphereOptions(p.medial, /*need_voxel_size=*/false);
}

absl::StatusOr<GeneratedCover> GenerateCover(const Solid& solid, const CoverParameters& parameters,
                                             const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckCoverParameters(parameters); !s.ok()) return s;
  const auto stage = [&control](double from, double to) {
    GenerationControl sub;
    sub.cancel = control.cancel;
    if (control.on_progress) {
      sub.on_progress = [&control, from, to](double f) {
        control.on_progress(from + (to - from) * f);
      };
    }
    return sub;
  };
  const auto cancelled = [&control] { return control.cancel != nullptr && control.cancel->load(); };

  SphereSetParameters internal;
  internal.max_spheres = parameters.max_spheres.value_or(kDefaultMaxSpheres);
  internal.medial = parameters.medial;
  internal.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> medial = GenerateSphereSet(solid, internal, stage(0.0, 0.4));
  if (!medial.ok()) return medial.status();
  if (medial->set.spheres.empty()) {
    return absl::FailedPreconditionError(
        "cover: the solid holds no medial sphere at this budget (no volume to grow from)");
  }
  GeneratedCover out;
  out.voxel_size = medial->voxel_size;
  std::vector<Sphere> spheres = std::move(medial->set.spheres);
  const std::vector<Sphere> internal_spheres = spheres;

  GrowToReach(GrowthPoints(solid.mesh(), parameters.growth_samples), &spheres);
  if (cancelled()) return absl::CancelledError("cover generation cancelled");
  if (control.on_progress) control.on_progress(0.5);

  CoverCertifyOptions certify = parameters.certify;
  certify.stop_at_witness =
      false;  // repairs grow a sphere around each failed cell: keep them small
  for (int round = 0;; ++round) {
    const double from = 0.5 + 0.5 * (1.0 - std::exp2(-round));
    absl::StatusOr<CoverCertificate> certificate =
        CertifyCover(solid, spheres, certify, stage(from, from + 0.5 * std::exp2(-round - 1)));
    if (!certificate.ok()) return certificate.status();
    if (certificate->certified) {
      out.certificate = *std::move(certificate);
      out.repair_rounds = round;
      break;
    }
    if (round + 1 == kMaxRounds) {
      return absl::InternalError(absl::StrCat("cover: still ", certificate->failed_cells,
                                              " unsettled cells after ", kMaxRounds, " repairs"));
    }
    GrowToContain(certificate->failures, &spheres);
  }
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    out.grown_spheres += spheres[i].radius > internal_spheres[i].radius;
  }
  out.set.spheres = std::move(spheres);
  if (control.on_progress) control.on_progress(1.0);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace inscribe
