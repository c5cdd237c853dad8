#include "inscribe/sphere_cover.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "cover_cells.h"
#include "cover_choice.h"
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
// Ladder bases per sphere of the budget (besides the vertices); the delta mode's bases.
constexpr std::int64_t kBasesPerSphere = 8;
constexpr std::int64_t kDeltaModeBases = 4'000;
// The first rung of the ladders and the sample grid's cell, as fractions of the bounding
// box's largest side.
constexpr double kFirstRung = 1.0 / 256;
// Halvings of the first rung tried where it lies past the medial axis (a thin part).
constexpr int kThinHalvings = 6;
constexpr double kGridCell = 1.0 / 64;
// Longest edge of the boundary's pieces each held whole by one sphere (a fraction of the
// largest side): a piece costs at most this much more growth than its best point.
constexpr double kBoundaryEdge = 1.0 / 1024;
// Steps of the search for the deepest centre on a normal (each shrinks the interval by 0.618).
constexpr int kGoldenSteps = 10;
// Thresholds the delta mode tries.
constexpr int kDeltaModeAttempts = 5;

// The chosen spheres grown to hold the boundary exactly, with `margin` to spare: every mesh
// triangle is cut into sub-triangles with edges of at most `edge`, and each goes whole to the
// sphere whose radius must grow least to hold its corners; a ball is convex, so it then holds
// the sub-triangle and every point within `margin` of it. The `interior` points go to spheres
// the same way. Radii only grow.
std::vector<Sphere> HoldBoundary(const Mesh& mesh, const std::vector<Sphere>& chosen,
                                 const std::vector<Vector3>& interior, double edge, double margin) {
  const std::size_t n = chosen.size();
  tbb::combinable<std::vector<double>> reaches([n] { return std::vector<double>(n, 0.0); });
  const auto growth = [&chosen](std::size_t i, const Vector3& p) {
    return (p - chosen[i].center).norm() - chosen[i].radius;
  };
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = i;
  // Splits a triangle in 4 (at its edges' midpoints) until its edges are short, keeping the
  // spheres that can still be best for a part of it: the growth to any point of a triangle is
  // within its diameter of the growth to its centroid.
  const std::function<void(const Vector3&, const Vector3&, const Vector3&,
                           const std::vector<std::size_t>&, std::vector<double>&)>
      hold = [&](const Vector3& p, const Vector3& q, const Vector3& r,
                 const std::vector<std::size_t>& candidates, std::vector<double>& reach) {
        const double diameter = std::max({(q - p).norm(), (r - p).norm(), (r - q).norm()});
        if (diameter <= edge) {
          std::size_t pick = candidates.front();
          double least = std::numeric_limits<double>::infinity();
          for (const std::size_t i : candidates) {
            const double g = std::max({growth(i, p), growth(i, q), growth(i, r)});
            if (g < least) {
              least = g;
              pick = i;
            }
          }
          const Vector3& o = chosen[pick].center;
          reach[pick] = std::max({reach[pick], (p - o).norm(), (q - o).norm(), (r - o).norm()});
          return;
        }
        const Vector3 centroid = (p + q + r) / 3.0;
        std::vector<double> at(candidates.size());
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          best = std::min(best, at[k] = growth(candidates[k], centroid));
        }
        std::vector<std::size_t> near;
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          if (at[k] <= best + 2.0 * diameter) near.push_back(candidates[k]);
        }
        const Vector3 pq = 0.5 * (p + q), qr = 0.5 * (q + r), rp = 0.5 * (r + p);
        hold(p, pq, rp, near, reach);
        hold(pq, q, qr, near, reach);
        hold(rp, qr, r, near, reach);
        hold(pq, qr, rp, near, reach);
      };
  tbb::parallel_for(Eigen::Index{0}, mesh.triangles.rows(), [&](Eigen::Index t) {
    hold(mesh.vertices.row(mesh.triangles(t, 0)).transpose(),
         mesh.vertices.row(mesh.triangles(t, 1)).transpose(),
         mesh.vertices.row(mesh.triangles(t, 2)).transpose(), all, reaches.local());
  });
  tbb::parallel_for(std::size_t{0}, interior.size(), [&](std::size_t p) {
    std::size_t pick = 0;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const double g = growth(i, interior[p]);
      if (g < least) {
        least = g;
        pick = i;
      }
    }
    double& reach = reaches.local()[pick];
    reach = std::max(reach, (interior[p] - chosen[pick].center).norm());
  });
  std::vector<double> reach(n, 0.0);
  reaches.combine_each([&reach](const std::vector<double>& local) {
    for (std::size_t i = 0; i < reach.size(); ++i) reach[i] = std::max(reach[i], local[i]);
  });

  std::vector<Sphere> out = chosen;
  for (std::size_t i = 0; i < n; ++i) {
    if (reach[i] > 0.0) {
      out[i].radius = std::max(out[i].radius, (reach[i] + margin) * (1.0 + kReachMargin));
    }
  }
  return out;
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

GenerationControl Stage(const GenerationControl& control, double from, double to) {
  GenerationControl sub;
  sub.cancel = control.cancel;
  if (control.on_progress) {
    sub.on_progress = [&control, from, to](double f) {
      control.on_progress(from + (to - from) * f);
    };
  }
  return sub;
}

// Inward normals of the base points: the face normal of the triangle a point lies on, the
// vertex normal at a vertex.
// The spheres a cover is chosen from. From each base point p of the boundary (the first
// `vertices` rows are mesh vertices) with inward normal n, centres c = p + s n on a ladder of
// depths s = s0, 2 s0, 4 s0, ... while c stays inside, each with radius depth(c): internal
// balls from tiny ones near the boundary (which reach a sharp feature with little growth) to
// the medial ball under p (which reaches far with little growth on flat parts).
// The deepest centre of each ladder is appended to `interior`.
// A ladder's base: a boundary point, and the mesh vertex it is (-1: a point of a triangle).
struct LadderBase {
  Vector3 point;
  std::int64_t vertex = -1;
};

std::vector<Sphere> Candidates(const Solid& solid, const std::vector<LadderBase>& base, double s0,
                               double s_max, std::vector<Vector3>* interior) {
  const BoundaryOracle& oracle = solid.oracle;
  const double factor = std::sqrt(2.0);
  int ladder = 1;
  while (s0 * std::pow(factor, ladder) <= s_max) ++ladder;
  const int rungs = ladder + 1;  // the last slot: the deepest centre on the normal
  std::vector<Sphere> slots(base.size() * static_cast<std::size_t>(rungs),
                            Sphere{Vector3::Zero(), 0.0});
  tbb::parallel_for(std::size_t{0}, base.size(), [&](std::size_t b) {
    const Vector3& p = base[b].point;
    Vector3 normal;
    if (base[b].vertex >= 0) {
      normal = oracle.vertex_normals()[static_cast<std::size_t>(base[b].vertex)];
    } else {
      normal = oracle.face_normals()[static_cast<std::size_t>(oracle.ClosestPoint(p).triangle)];
    }
    Sphere* slot = &slots[b * static_cast<std::size_t>(rungs)];
    // Depth of the centre at distance s along the inward normal; 0 outside.
    const auto depth = [&](double s) {
      const Vector3 c = p - s * normal;
      const BoundaryPoint closest = oracle.ClosestPoint(c);
      return oracle.Classify(c, closest) == Side::kInside ? closest.distance : 0.0;
    };
    // The solid may lie on the normal's other side (a triangle the mesh orients against its
    // neighbours; a vertex where such triangles meet); a part thinner than 2 s0 has its
    // medial axis before the first rung: start lower there.
    if (!(normal.norm() > 0.0)) return;
    normal.normalize();
    double first = s0;
    for (int halvings = 0; halvings <= kThinHalvings; ++halvings, first *= 0.5) {
      if (depth(first) > 0.0) break;
      if (depth(-first) > 0.0) {
        normal = -normal;
        break;
      }
    }
    double last = 0.0, last_s = 0.0, before_s = 0.0;
    int k = 0;
    for (; k < ladder; ++k) {
      const double s = first * std::pow(factor, k);
      const double d = depth(s);
      // Past the medial axis the centre nears another part of the boundary: stop.
      if (d <= last) break;
      slot[k] = Sphere{p - s * normal, d};
      last = d;
      before_s = last_s;
      last_s = s;
    }
    if (k == 0) return;
    // The deepest centre lies between the rung before the last and the first that failed:
    // a golden-section search of the depth along the normal.
    double lo = before_s, hi = k < ladder ? first * std::pow(factor, k) : last_s;
    const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
    double m1 = hi - phi * (hi - lo), m2 = lo + phi * (hi - lo);
    double d1 = depth(m1), d2 = depth(m2);
    for (int step = 0; step < kGoldenSteps; ++step) {
      if (d1 < d2) {
        lo = m1;
        m1 = m2;
        d1 = d2;
        m2 = lo + phi * (hi - lo);
        d2 = depth(m2);
      } else {
        hi = m2;
        m2 = m1;
        d2 = d1;
        m1 = hi - phi * (hi - lo);
        d1 = depth(m1);
      }
    }
    const double s = 0.5 * (lo + hi), d = depth(s);
    if (d > last) slot[ladder] = Sphere{p - s * normal, d};
  });
  std::vector<Sphere> out;
  for (std::size_t b = 0; b < base.size(); ++b) {
    const Sphere* deepest = nullptr;
    for (int k = 0; k < rungs; ++k) {
      const Sphere& s = slots[b * static_cast<std::size_t>(rungs) + static_cast<std::size_t>(k)];
      if (s.radius > 0.0) {
        out.push_back(s);
        deepest = &s;
      }
    }
    if (deepest != nullptr) interior->push_back(deepest->center);
  }
  return out;
}

// Certifies `spheres`, growing spheres around the cells it could not settle until it passes.
absl::StatusOr<CoverCertificate> CertifyAndRepair(const Solid& solid,
                                                  const CoverParameters& parameters,
                                                  std::vector<Sphere>* spheres, int* rounds,
                                                  const GenerationControl& control) {
  CoverCertifyOptions certify = parameters.certify;
  certify.stop_at_witness = false;  // repairs grow a sphere around each failed cell: keep
                                    // them small
  for (int round = 0;; ++round) {
    const double from = 1.0 - std::exp2(-round);
    absl::StatusOr<CoverCertificate> certificate =
        CertifyCover(solid, *spheres, certify, Stage(control, from, from + std::exp2(-round - 1)));
    if (!certificate.ok()) return certificate.status();
    if (certificate->certified) {
      *rounds = round;
      return certificate;
    }
    if (round + 1 == kMaxRounds) {
      return absl::InternalError(absl::StrCat("cover: still ", certificate->failed_cells,
                                              " unsettled cells after ", kMaxRounds, " repairs"));
    }
    GrowToContain(certificate->failures, spheres);
  }
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
  return CheckCoverCertifyOptions(p.certify);
}

absl::StatusOr<GeneratedCover> GenerateCover(const Solid& solid, const CoverParameters& parameters,
                                             const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckCoverParameters(parameters); !s.ok()) return s;
  const Mesh& mesh = solid.mesh();
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const double scale = box.extent().maxCoeff();
  const internal::OctreeFrame frame = internal::MakeOctreeFrame(box, parameters.certify.resolution);
  // Every finest cell of the certificate that meets the boundary lies within its diagonal of
  // a boundary point, so inside one sphere when every boundary point has that much room in
  // one sphere: the cover passes at the first certificate.
  const double margin = std::sqrt(3.0) * frame.finest_side() * (1.0 + 1e-6);
  const double edge = kBoundaryEdge * scale;
  if (parameters.max_protrusion && *parameters.max_protrusion <= margin) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: max_protrusion ", *parameters.max_protrusion,
                     " is within the certificate's finest cell diagonal ", margin,
                     " (raise it, or refine the certificate's resolution)"));
  }

  // The boundary points a cover must reach, and the bases of the candidate ladders: every
  // vertex and the first area samples.
  internal::CoverSamples samples;
  const Vertices drawn =
      internal::SampleBoundaryByArea(mesh, parameters.growth_samples, kGrowthSeed);
  // Vertices (the corners of sharp features), as many as the area samples at most.
  const Eigen::Index vertex_stride = std::max<Eigen::Index>(
      1, (mesh.vertices.rows() + drawn.rows() - 1) / std::max<Eigen::Index>(1, drawn.rows()));
  std::vector<std::int64_t> sampled_vertices;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); v += vertex_stride) {
    samples.points.push_back(mesh.vertices.row(v).transpose());
    sampled_vertices.push_back(v);
  }
  for (Eigen::Index i = 0; i < drawn.rows(); ++i) {
    samples.points.push_back(drawn.row(i).transpose());
  }
  const std::int64_t budget = parameters.max_spheres.value_or(kDefaultMaxSpheres);
  // As many vertices as area samples at most (evenly spread through the vertex list).
  const std::int64_t per_kind =
      parameters.max_protrusion ? kDeltaModeBases : kBasesPerSphere * budget;
  std::vector<LadderBase> bases;
  const std::size_t stride = (sampled_vertices.size() + per_kind - 1) / per_kind;
  for (std::size_t i = 0; i < sampled_vertices.size(); i += stride) {
    bases.push_back({samples.points[i], sampled_vertices[i]});
  }
  for (Eigen::Index i = 0; i < std::min<Eigen::Index>(drawn.rows(), per_kind); ++i) {
    bases.push_back({drawn.row(i).transpose(), -1});
  }
  std::vector<Vector3> interior;
  const std::vector<Sphere> candidates =
      Candidates(solid, bases, scale * kFirstRung, scale / 2, &interior);
  if (candidates.empty()) {
    return absl::FailedPreconditionError("cover: the solid has no interior to cover");
  }
  samples.points.insert(samples.points.end(), interior.begin(), interior.end());
  const internal::PointGrid grid(samples.points, scale * kGridCell);
  if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
  if (control.on_progress) control.on_progress(0.2);

  // The chosen candidates, holding the boundary with margin, certified (repaired if need be).
  const auto finish = [&](const std::vector<std::size_t>& chosen,
                          const GenerationControl& stage) -> absl::StatusOr<GeneratedCover> {
    std::vector<Sphere> spheres;
    spheres.reserve(chosen.size());
    for (const std::size_t i : chosen) spheres.push_back(candidates[i]);
    spheres = HoldBoundary(mesh, spheres, interior, edge, margin);
    GeneratedCover out;
    out.candidates = static_cast<std::int64_t>(candidates.size());
    const std::vector<Sphere> held = spheres;
    absl::StatusOr<CoverCertificate> certificate =
        CertifyAndRepair(solid, parameters, &spheres, &out.repair_rounds, stage);
    if (!certificate.ok()) return certificate.status();
    out.certificate = *std::move(certificate);
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      out.grown_spheres += spheres[i].radius > held[i].radius;
    }
    out.set.spheres = std::move(spheres);
    return out;
  };

  absl::StatusOr<GeneratedCover> out;
  if (!parameters.max_protrusion) {
    const std::vector<std::size_t> chosen = internal::ChooseForBudget(
        candidates, samples, grid, static_cast<std::size_t>(budget), control);
    if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
    if (control.on_progress) control.on_progress(0.5);
    out = finish(chosen, Stage(control, 0.5, 1.0));
  } else {
    // The delta mode: the fewest candidates reaching every sample within a threshold t, with
    // t moved until the certified delta is just within the bound (delta exceeds t by the
    // margin and the boundary between samples).
    const double bound = *parameters.max_protrusion;
    double t = 0.5 * (bound - margin);
    double unreachable = 0.0;  // a threshold at which some sample is out of every reach
    double least = std::numeric_limits<double>::infinity();  // certified delta, any attempt
    for (int attempt = 0; attempt < kDeltaModeAttempts; ++attempt) {
      if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
      const internal::ReachLists lists = internal::MakeReachLists(candidates, samples, grid, t);
      const std::optional<std::vector<std::size_t>> chosen =
          internal::GreedyCover(lists, samples.points.size(), t, candidates.size());
      if (!chosen) {
        unreachable = t;
        if (t >= bound - margin) break;
        t = 0.5 * (t + bound - margin);
        continue;
      }
      const double from = 0.2 + 0.8 * attempt / kDeltaModeAttempts;
      absl::StatusOr<GeneratedCover> tried =
          finish(*chosen, Stage(control, from, from + 0.8 / kDeltaModeAttempts));
      if (!tried.ok()) return tried.status();
      const double delta = tried->certificate.delta;
      least = std::min(least, delta);
      if (delta <= bound) {
        if (!out.ok() || tried->set.size() < out->set.size()) out = *std::move(tried);
        t += 0.5 * (bound - delta);  // room left: a larger threshold needs fewer spheres
      } else {
        t -= 1.2 * (delta - bound);  // over by this much: aim lower
        if (t <= unreachable) break;
      }
    }
    if (!out.ok()) {
      return absl::FailedPreconditionError(absl::StrCat(
          "cover: no certified cover within max_protrusion ", bound,
          "; the least delta reached was ",
          std::isfinite(least) ? absl::StrCat(least) : absl::StrCat("above ", unreachable + margin),
          " (ask for a larger max_protrusion, or a sphere budget)"));
    }
  }
  if (!out.ok()) return out.status();
  if (control.on_progress) control.on_progress(1.0);
  out->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace inscribe
