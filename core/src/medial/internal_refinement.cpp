#include "inscribe/medial/internal_refinement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/balls/union_of_balls.h"

namespace inscribe {
namespace {

// Unit directions of a Fibonacci lattice with n points, each standing for 4 pi / n of area.
std::vector<Vector3> FibonacciDirections(int n) {
  std::vector<Vector3> out;
  out.reserve(n);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    out.emplace_back(s * std::cos(golden * k), s * std::sin(golden * k), z);
  }
  return out;
}

// d/dr_i and d/dc_i of the union volume, estimated from the exposed samples of each sphere.
void Gradient(const std::vector<Sphere>& balls, const std::vector<Vector3>& directions,
              std::vector<double>* grad_r, std::vector<Vector3>* grad_c) {
  const std::size_t n = balls.size();
  grad_r->assign(n, 0.0);
  grad_c->assign(n, Vector3::Zero());
  const double cell_area = 4.0 * M_PI / static_cast<double>(directions.size());
  std::vector<std::int32_t> near;
  for (std::size_t i = 0; i < n; ++i) {
    near.clear();
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const double reach = balls[i].radius + balls[j].radius;
      if ((balls[i].center - balls[j].center).squaredNorm() < reach * reach) {
        near.push_back(static_cast<std::int32_t>(j));
      }
    }
    const double area = cell_area * balls[i].radius * balls[i].radius;
    for (const Vector3& u : directions) {
      const Vector3 x = balls[i].center + balls[i].radius * u;
      bool covered = false;
      for (const std::int32_t j : near) {
        const double rj = balls[j].radius;
        if ((x - balls[j].center).squaredNorm() < rj * rj) {
          covered = true;
          break;
        }
      }
      if (covered) continue;
      (*grad_r)[i] += area;
      (*grad_c)[i] += area * u;
    }
  }
}

// The ball a step proposes, projected inside: the old ball when the new centre is not inside.
Sphere Project(const BoundaryOracle& oracle, const Sphere& old, const Vector3& center,
               double radius) {
  const double signed_distance = oracle.SignedDistance(center);
  if (!(signed_distance < 0.0)) return old;
  const double r = std::min(radius, -signed_distance * (1.0 - 1e-9));
  if (!(r > 0.0)) return old;
  return Sphere{center, r};
}

}  // namespace

absl::Status CheckInternalRefinementOptions(const InternalRefinementOptions& options) {
  if (options.iterations < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("iterations must be >= 0, got ", options.iterations));
  }
  if (options.samples_per_sphere < 16) {
    return absl::InvalidArgumentError(
        absl::StrCat("samples_per_sphere must be >= 16, got ", options.samples_per_sphere));
  }
  return absl::OkStatus();
}

absl::StatusOr<InternalRefinement> RefineInternalSpheres(const BoundaryOracle& oracle,
                                                         const std::vector<Sphere>& spheres,
                                                         const InternalRefinementOptions& options) {
  if (absl::Status s = CheckInternalRefinementOptions(options); !s.ok()) return s;
  if (absl::Status s = CheckSpheres(spheres); !s.ok()) return s;
  InternalRefinement out;
  out.spheres = spheres;
  absl::StatusOr<double> volume = UnionVolume(out.spheres);
  if (!volume.ok()) return volume.status();
  out.volume_before = out.volume_after = *volume;
  if (spheres.empty()) return out;
  double mean_radius = 0.0;
  for (const Sphere& b : spheres) mean_radius += b.radius;
  mean_radius /= static_cast<double>(spheres.size());
  // Largest move of any centre or radius in a step, mesh units.
  double step = 0.05 * mean_radius;
  const std::vector<Vector3> directions = FibonacciDirections(options.samples_per_sphere);
  std::vector<double> grad_r;
  std::vector<Vector3> grad_c;
  std::vector<double> raw_r;  // the gradient before the tangent balls' change of variables
  std::vector<Vector3> raw_c;
  std::vector<Vector3> away(spheres.size());  // tangent balls: unit direction from the contact
  std::vector<Sphere> trial(spheres.size());
  for (int it = 0; it < options.iterations; ++it) {
    ++out.iterations;
    Gradient(out.spheres, directions, &grad_r, &grad_c);
    raw_r = grad_r;
    raw_c = grad_c;
    // A ball touching the boundary stays tangent: its radius follows d(c), so its centre moves
    // along gc + gr grad d, with grad d the unit direction from its nearest boundary point.
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      const Sphere& b = out.spheres[i];
      const BoundaryPoint foot = oracle.ClosestPoint(b.center);
      if (b.radius >= foot.distance * (1.0 - 1e-6) && foot.distance > 0.0) {
        away[i] = (b.center - foot.point) / foot.distance;
        grad_c[i] += grad_r[i] * away[i];
        grad_r[i] = std::numeric_limits<double>::infinity();  // r := d(c') in Project
      }
    }
    double largest = 0.0;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      largest = std::max(largest, grad_c[i].norm());
      if (std::isfinite(grad_r[i])) largest = std::max(largest, std::abs(grad_r[i]));
    }
    if (!(largest > 0.0)) break;
    bool accepted = false;
    for (int halving = 0; halving <= 8 && !accepted; ++halving, step *= 0.5) {
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        const Sphere& b = out.spheres[i];
        // Each ball moves up to `step` along its own gradient (a sign-like step: balls with
        // little exposed area move as far as the others). The distance has a kink where a ball
        // touches at several points (every medial ball), so a tangent ball tries three
        // directions (the change of variables, the centre's own gradient, and that gradient
        // with its part towards the known contact removed) and keeps the one whose projected
        // move gains most to first order in the volume's gradient; no move without a gain.
        trial[i] = b;
        double best = 0.0;
        auto consider = [&](const Vector3& dc, double dr) {
          double own = dc.norm();
          if (std::isfinite(dr)) own = std::max(own, std::abs(dr));
          if (!(own > 0.0)) return;
          const double scale = step / own;
          const Sphere moved = Project(oracle, b, b.center + scale * dc, b.radius + scale * dr);
          const double gain =
              raw_c[i].dot(moved.center - b.center) + raw_r[i] * (moved.radius - b.radius);
          if (gain > best) {
            best = gain;
            trial[i] = moved;
          }
        };
        consider(grad_c[i], grad_r[i]);
        if (!std::isfinite(grad_r[i])) {
          consider(raw_c[i], grad_r[i]);
          consider(raw_c[i] - raw_c[i].dot(away[i]) * away[i], grad_r[i]);
        }
      }
      absl::StatusOr<double> v = UnionVolume(trial);
      if (!v.ok()) return v.status();
      if (*v > out.volume_after) {
        out.volume_after = *v;
        std::swap(out.spheres, trial);
        trial.resize(spheres.size());
        ++out.accepted;
        accepted = true;
        step = std::min(3.0 * step, 0.5 * mean_radius);  // halved once more by the loop
      }
    }
    if (!accepted) break;
  }
  return out;
}

}  // namespace inscribe
