// ComputeEnvelopeDistances: see envelope_distances.h.
#include "inscribe/distance/envelope_distances.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "mesh/surface_sampling.h"

namespace inscribe {
namespace {

constexpr std::int64_t kMaxSamples = 100'000'000;

// Nodes with at most this many spheres are scanned sphere by sphere instead of descended.
constexpr std::int32_t kScanCount = 4;

// A node is pruned only when its bound beats the current answer by more than this, relative to
// the lengths involved: the bound |p - C| - R is a true lower bound, but computed in floating
// point it may exceed a ball's computed gap by a few ulps. With the slack, pruning never drops a
// ball the scan would pick, so the answers equal a scan's bit for bit.
constexpr double kPruneSlack = 1e-12;

// |p - c| - r, computed exactly as a scan over the balls computes it.
double Gap(const Vector3& p, const Sphere& s) { return (p - s.center).norm() - s.radius; }

// Smallest Gap(p, ball) over all balls. Depth first over the hierarchy's slots, nearer child
// first; a node is skipped when the gap to the sphere around it cannot beat the best so far.
double SmallestGap(const SphereHierarchy& tree, const Vector3& p) {
  using Slot = SphereHierarchy::Slot;
  const std::vector<Sphere>& ordered = tree.ordered_spheres();
  double best = std::numeric_limits<double>::infinity();
  thread_local std::vector<HierarchyRef> stack;  // kept between queries: no allocation per query
  stack.clear();
  stack.push_back(tree.root());
  while (!stack.empty()) {
    const Slot& slot = tree.slot(stack.back());
    stack.pop_back();
    const double centre_distance = (p - slot.center).norm();
    if (centre_distance - slot.radius - kPruneSlack * (centre_distance + slot.radius) > best) {
      continue;
    }
    if (slot.count <= kScanCount) {
      for (std::int32_t k = slot.first; k < slot.first + slot.count; ++k) {
        best = std::min(best, Gap(p, ordered[static_cast<std::size_t>(k)]));
      }
      continue;
    }
    const Slot& left = tree.slot(slot.left);
    const Slot& right = tree.slot(slot.right);
    const double left_bound = (p - left.center).norm() - left.radius;
    const double right_bound = (p - right.center).norm() - right.radius;
    // Pushed last, popped first: the nearer child.
    if (left_bound < right_bound) {
      stack.push_back(slot.right);
      stack.push_back(slot.left);
    } else {
      stack.push_back(slot.left);
      stack.push_back(slot.right);
    }
  }
  return best;
}

// Whether q, a point on sphere `own`, is off the envelope: strictly inside another ball, or on
// an exactly equal sphere of lower index (so that of equal spheres only the first counts).
bool IsCoveredByAnotherBall(const SphereHierarchy& tree, const Vector3& q, std::int32_t own) {
  using Slot = SphereHierarchy::Slot;
  const std::vector<Sphere>& ordered = tree.ordered_spheres();
  const std::vector<std::int32_t>& order = tree.leaf_order();
  const Sphere& own_sphere = tree.spheres()[static_cast<std::size_t>(own)];
  thread_local std::vector<HierarchyRef> stack;
  stack.clear();
  stack.push_back(tree.root());
  while (!stack.empty()) {
    const Slot& slot = tree.slot(stack.back());
    stack.pop_back();
    // A point strictly inside a ball is strictly inside every sphere around that ball.
    const double centre_distance = (q - slot.center).norm();
    if (centre_distance - slot.radius > kPruneSlack * (centre_distance + slot.radius)) continue;
    if (slot.count <= kScanCount) {
      for (std::int32_t k = slot.first; k < slot.first + slot.count; ++k) {
        const std::int32_t j = order[static_cast<std::size_t>(k)];
        if (j == own) continue;
        const Sphere& s = ordered[static_cast<std::size_t>(k)];
        if (s.center == own_sphere.center && s.radius == own_sphere.radius) {
          if (j < own) return true;
          continue;
        }
        if ((q - s.center).squaredNorm() < s.radius * s.radius) return true;
      }
      continue;
    }
    stack.push_back(slot.left);
    stack.push_back(slot.right);
  }
  return false;
}

SignedDistanceSummary Summarize(const std::vector<double>& values) {
  SignedDistanceSummary out;
  if (values.empty()) return out;
  double sum = 0.0, sum_absolute = 0.0;
  out.min = std::numeric_limits<double>::infinity();
  out.max = -std::numeric_limits<double>::infinity();
  // Serial, in sample order: the same sums on every run.
  for (double v : values) {
    sum += v;
    sum_absolute += std::abs(v);
    out.min = std::min(out.min, v);
    out.max = std::max(out.max, v);
  }
  out.mean = sum / static_cast<double>(values.size());
  out.mean_absolute = sum_absolute / static_cast<double>(values.size());
  return out;
}

absl::Status CheckRequest(const std::vector<Sphere>& spheres,
                          const EnvelopeDistanceRequest& request) {
  if (spheres.empty()) {
    return absl::InvalidArgumentError("no spheres: the union of an empty set has no envelope");
  }
  if (absl::Status status = CheckSpheres(spheres); !status.ok()) {
    return status;
  }
  for (const auto& [name, count] : {std::pair{"boundary", request.boundary_samples},
                                    std::pair{"envelope", request.envelope_samples}}) {
    if (count < 0 || count > kMaxSamples) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, " samples must lie in [0, ", kMaxSamples, "], got ", count));
    }
  }
  if (request.max_attempts_per_sample < 1) {
    return absl::InvalidArgumentError(absl::StrCat("max attempts per sample must be >= 1, got ",
                                                   request.max_attempts_per_sample));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<EnvelopeDistanceResult> ComputeEnvelopeDistances(
    const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
    const EnvelopeDistanceRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status status = CheckRequest(spheres, request); !status.ok()) return status;
  absl::StatusOr<SphereHierarchy> tree = SphereHierarchy::Build(spheres, HierarchyVolume::kSphere);
  if (!tree.ok()) return tree.status();
  EnvelopeDistanceResult result;

  // Boundary to envelope.
  if (request.boundary_samples > 0) {
    result.boundary_points =
        internal::SampleBoundaryByArea(oracle.mesh(), request.boundary_samples, request.seed);
    if (result.boundary_points.rows() == 0) {
      return absl::InvalidArgumentError("the mesh has no triangle of positive area to sample");
    }
    result.boundary_to_envelope.resize(static_cast<std::size_t>(request.boundary_samples));
    internal::ParallelForRange(
        std::int64_t{0}, request.boundary_samples, 256, [&](std::int64_t begin, std::int64_t end) {
          for (std::int64_t i = begin; i != end; ++i) {
            result.boundary_to_envelope[static_cast<std::size_t>(i)] =
                -SmallestGap(*tree, result.boundary_points.row(i).transpose());
          }
        });
    result.boundary_to_envelope_summary = Summarize(result.boundary_to_envelope);
  }

  // Envelope to boundary.
  const std::int64_t m = request.envelope_samples;
  if (m > 0) {
    std::vector<double> cumulative(spheres.size());
    double total = 0.0;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      total += spheres[i].radius * spheres[i].radius;
      cumulative[i] = total;
    }
    result.envelope_points.resize(m, 3);
    result.envelope_sphere.resize(static_cast<std::size_t>(m));
    result.envelope_to_boundary.resize(static_cast<std::size_t>(m));
    std::vector<std::int64_t> attempts(static_cast<std::size_t>(m), 0);
    std::atomic<bool> exhausted{false};
    internal::ParallelForRange(std::int64_t{0}, m, 64, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t k = begin; k != end; ++k) {
        if (exhausted.load(std::memory_order_relaxed)) return;
        // One generator per sample, seeded by (seed, k) apart from the boundary samples'
        // streams: the points do not depend on scheduling.
        const auto kk = static_cast<std::uint64_t>(k);
        std::seed_seq seq{static_cast<std::uint32_t>(request.seed),
                          static_cast<std::uint32_t>(request.seed >> 32),
                          static_cast<std::uint32_t>(kk), static_cast<std::uint32_t>(kk >> 32),
                          std::uint32_t{2}};
        std::mt19937_64 random(seq);
        auto uniform = [&random] { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
        std::int64_t tries = 0;
        for (;;) {
          if (++tries > request.max_attempts_per_sample) {
            exhausted.store(true, std::memory_order_relaxed);
            return;
          }
          const std::int32_t own = static_cast<std::int32_t>(std::min<std::ptrdiff_t>(
              static_cast<std::ptrdiff_t>(spheres.size()) - 1,
              std::upper_bound(cumulative.begin(), cumulative.end(), uniform() * total) -
                  cumulative.begin()));
          const double z = 2.0 * uniform() - 1.0;
          const double phi = 2.0 * M_PI * uniform();
          const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
          const Sphere& s = spheres[static_cast<std::size_t>(own)];
          const Vector3 q =
              s.center + s.radius * Vector3(ring * std::cos(phi), ring * std::sin(phi), z);
          if (IsCoveredByAnotherBall(*tree, q, own)) continue;
          result.envelope_points.row(k) = q.transpose();
          result.envelope_sphere[static_cast<std::size_t>(k)] = own;
          result.envelope_to_boundary[static_cast<std::size_t>(k)] = oracle.SignedDistance(q);
          attempts[static_cast<std::size_t>(k)] = tries;
          break;
        }
      }
    });
    if (exhausted.load()) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "an envelope sample needed more than ", request.max_attempts_per_sample,
          " candidate points: the envelope is a vanishing part of the spheres' total area "
          "(many nested or repeated spheres?)"));
    }
    for (std::int64_t a : attempts) result.envelope_attempts += a;
    result.envelope_area =
        4.0 * M_PI * total * static_cast<double>(m) / static_cast<double>(result.envelope_attempts);
    result.envelope_to_boundary_summary = Summarize(result.envelope_to_boundary);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace inscribe
