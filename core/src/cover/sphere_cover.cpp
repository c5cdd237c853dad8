#include "inscribe/cover/sphere_cover.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <queue>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "cover/cover_cells.h"
#include "cover/cover_choice.h"
#include "mesh/surface_sampling.h"

namespace inscribe {
namespace {

// A sphere grown to reach a point or a cell's corner reaches this much farther (relative),
// far above rounding, so the certificate's own margin (1e-12 on squares) is met.
constexpr double kReachMargin = 1e-9;
// Fixed, so that covers are reproducible.
constexpr std::uint64_t kGrowthSeed = 0x636f766572;  // "cover"
constexpr int kMaxRounds = 8;
// Ladder bases per sphere of the budget (besides the vertices).
constexpr std::int64_t kBasesPerSphere = 8;
// The first rung of the ladders and the sample grid's cell, as fractions of the bounding
// box's largest side.
constexpr double kFirstRung = 1.0 / 256;
// Halvings of the first rung tried where it lies past the medial axis (a thin part).
constexpr int kThinHalvings = 6;
constexpr double kGridCell = 1.0 / 64;
// Growth a boundary piece held whole may cost beyond its best point, and the longest edge a
// piece is split to (both a fraction of the largest side).
constexpr double kBoundaryEdge = 1.0 / 1024;
// Steps of the search for the deepest centre on a normal (each shrinks the interval by 0.618).
constexpr int kGoldenSteps = 10;
// The delta mode's budgets: the first it makes candidates for and the most; the covers it
// generates at most, and the share of the bound it aims at when predicting a budget.
constexpr std::int64_t kDeltaModeFirstBudget = 32;
constexpr std::int64_t kDeltaModeMaxBudget = 2'048;
constexpr int kDeltaModeAttempts = 6;
constexpr double kDeltaModeAim = 0.95;
// Boundary samples a budget's choice reaches, per sphere of the budget, and at least (up to
// CoverParameters::growth_samples): few spheres are large, and reach far between samples.
constexpr std::int64_t kGrowthSamplesPerSphere = 40;
constexpr std::int64_t kMinGrowthSamples = 2'000;

// A grain that cuts `count` items into about 64 chunks: enough for the threads to share, few
// enough that each chunk's copy of a per-sphere array costs little.
std::size_t ReduceGrain(std::size_t count) { return std::max<std::size_t>(count / 64, 1); }

// The chosen spheres grown to hold the boundary exactly, with `margin` to spare: every mesh
// triangle goes whole to the sphere whose radius must grow least to hold its corners, or is
// split in four until that costs at most `edge` more than the least growth any sphere needs at
// its centroid (or its edges are at most `edge`); a ball is convex, so it then holds the piece
// and every point within `margin` of it. Large flat triangles (boxes, CAD meshes) that lie
// mostly inside one sphere are held without splitting them down. The `interior` points go to
// spheres the same way. Radii only grow.
std::vector<Sphere> HoldBoundary(const Mesh& mesh, const std::vector<Sphere>& chosen,
                                 const std::vector<Vector3>& interior, double edge, double margin) {
  const std::size_t n = chosen.size();
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
        // The sphere that holds the whole piece with the least growth (a ball holds a
        // triangle when it holds its corners), and the least growth any sphere needs at the
        // centroid, which no finer split can go below at that point.
        std::size_t pick = candidates.front();
        double least = std::numeric_limits<double>::infinity();
        for (const std::size_t i : candidates) {
          const double g = std::max({growth(i, p), growth(i, q), growth(i, r)});
          if (g < least) {
            least = g;
            pick = i;
          }
        }
        const Vector3 centroid = (p + q + r) / 3.0;
        std::vector<double> at(candidates.size());
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          best = std::min(best, at[k] = growth(candidates[k], centroid));
        }
        // Whole, when splitting could save at most `edge` of growth (or the piece is small).
        if (diameter <= edge || least <= std::max(best, 0.0) + edge) {
          const Vector3& o = chosen[pick].center;
          reach[pick] = std::max({reach[pick], (p - o).norm(), (q - o).norm(), (r - o).norm()});
          return;
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
  // Each chunk's reaches, joined by their maximum.
  const auto farther = [](std::vector<double> a, std::vector<double> b) {
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::max(a[i], b[i]);
    return a;
  };
  const std::vector<double> none(n, 0.0);
  const Eigen::Index triangles = mesh.triangles.rows();
  const std::vector<double> held = internal::ParallelReduce(
      Eigen::Index{0}, triangles, ReduceGrain(static_cast<std::size_t>(triangles)), none,
      [&](Eigen::Index begin, Eigen::Index end, std::vector<double> reach) {
        for (Eigen::Index t = begin; t < end; ++t) {
          hold(mesh.vertices.row(mesh.triangles(t, 0)).transpose(),
               mesh.vertices.row(mesh.triangles(t, 1)).transpose(),
               mesh.vertices.row(mesh.triangles(t, 2)).transpose(), all, reach);
        }
        return reach;
      },
      farther);
  const std::vector<double> reach = farther(
      held, internal::ParallelReduce(
                std::size_t{0}, interior.size(), ReduceGrain(interior.size()), none,
                [&](std::size_t begin, std::size_t end, std::vector<double> local) {
                  for (std::size_t p = begin; p < end; ++p) {
                    std::size_t pick = 0;
                    double least = std::numeric_limits<double>::infinity();
                    for (std::size_t i = 0; i < n; ++i) {
                      const double g = growth(i, interior[p]);
                      if (g < least) {
                        least = g;
                        pick = i;
                      }
                    }
                    local[pick] = std::max(local[pick], (interior[p] - chosen[pick].center).norm());
                  }
                  return local;
                },
                farther));

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

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
  internal::ParallelFor(std::size_t{0}, base.size(), [&](std::size_t b) {
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

// What a cover is chosen from, made once for every budget asked of it.
struct PreparedCover::State {
  const Solid* solid = nullptr;
  CoverParameters parameters;
  double scale = 0.0;   // the bounding box's largest side
  double margin = 0.0;  // one finest certificate cell's diagonal (and a little)
  double edge = 0.0;    // the boundary pieces' longest edge (HoldBoundary)
  internal::CoverSamples samples;
  std::vector<Sphere> candidates;
  std::vector<Vector3> interior;
  std::unique_ptr<internal::PointGrid> grid;  // over samples.points
  double prepare_seconds = 0.0;
};

namespace {

// Boundary samples the choice reaches: fewer for small budgets (see kGrowthSamplesPerSphere).
std::int64_t CoverGrowthSamples(const CoverParameters& parameters) {
  const std::int64_t budget = parameters.max_spheres.value_or(kDefaultMaxSpheres);
  const std::int64_t wanted = std::max(kMinGrowthSamples, kGrowthSamplesPerSphere * budget);
  return std::min(parameters.growth_samples, wanted);
}

}  // namespace

absl::StatusOr<PreparedCover> PreparedCover::Prepare(const Solid& solid,
                                                     const CoverParameters& parameters,
                                                     const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckCoverParameters(parameters); !s.ok()) return s;
  auto state = std::make_shared<State>();
  state->solid = &solid;
  state->parameters = parameters;
  const Mesh& mesh = solid.mesh();
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  state->scale = box.extent().maxCoeff();
  const internal::OctreeFrame frame = internal::MakeOctreeFrame(box, parameters.certify.resolution);
  // Every finest cell of the certificate that meets the boundary lies within its diagonal of
  // a boundary point, so inside one sphere when every boundary point has that much room in
  // one sphere: the cover passes at the first certificate.
  state->margin = std::sqrt(3.0) * frame.finest_side() * (1.0 + 1e-6);
  state->edge = kBoundaryEdge * state->scale;

  // The boundary points a cover must reach, and the bases of the candidate ladders: every
  // vertex and the first area samples.
  internal::CoverSamples& samples = state->samples;
  const Vertices drawn =
      internal::SampleBoundaryByArea(mesh, CoverGrowthSamples(parameters), kGrowthSeed);
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
  const std::int64_t per_kind = kBasesPerSphere * budget;
  std::vector<LadderBase> bases;
  const std::size_t stride = (sampled_vertices.size() + per_kind - 1) / per_kind;
  for (std::size_t i = 0; i < sampled_vertices.size(); i += stride) {
    bases.push_back({samples.points[i], sampled_vertices[i]});
  }
  for (Eigen::Index i = 0; i < std::min<Eigen::Index>(drawn.rows(), per_kind); ++i) {
    bases.push_back({drawn.row(i).transpose(), -1});
  }
  state->candidates =
      Candidates(solid, bases, state->scale * kFirstRung, state->scale / 2, &state->interior);
  if (state->candidates.empty()) {
    return absl::FailedPreconditionError("cover: the solid has no interior to cover");
  }
  samples.points.insert(samples.points.end(), state->interior.begin(), state->interior.end());
  state->grid = std::make_unique<internal::PointGrid>(samples.points, state->scale * kGridCell);
  if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
  state->prepare_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return PreparedCover(std::move(state));
}

PreparedCover::PreparedCover(std::shared_ptr<const State> state) : state_(std::move(state)) {}

const Solid& PreparedCover::solid() const { return *state_->solid; }

double PreparedCover::margin() const { return state_->margin; }

std::vector<double> PreparedCover::EstimatedDeltas(std::int64_t max_spheres) const {
  std::vector<double> out = internal::FarthestFirstThresholds(
      state_->candidates, state_->samples,
      static_cast<std::size_t>(std::max<std::int64_t>(max_spheres, 1)));
  for (double& t : out) t += state_->margin;
  return out;
}

absl::StatusOr<GeneratedCover> PreparedCover::Finish(const std::vector<std::size_t>& chosen,
                                                     const GenerationControl& stage) const {
  const State& s = *state_;
  std::vector<Sphere> spheres;
  spheres.reserve(chosen.size());
  for (const std::size_t i : chosen) spheres.push_back(s.candidates[i]);
  spheres = HoldBoundary(s.solid->mesh(), spheres, s.interior, s.edge, s.margin);
  GeneratedCover out;
  out.candidates = static_cast<std::int64_t>(s.candidates.size());
  const std::vector<Sphere> held = spheres;
  absl::StatusOr<CoverCertificate> certificate =
      CertifyAndRepair(*s.solid, s.parameters, &spheres, &out.repair_rounds, stage);
  if (!certificate.ok()) return certificate.status();
  out.certificate = *std::move(certificate);
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    out.grown_spheres += spheres[i].radius > held[i].radius;
  }
  out.set.spheres = std::move(spheres);
  return out;
}

absl::StatusOr<GeneratedCover> PreparedCover::Generate(std::int64_t max_spheres,
                                                       const GenerationControl& control) const {
  const auto start = std::chrono::steady_clock::now();
  if (max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: max_spheres must be positive, got ", max_spheres));
  }
  const State& s = *state_;
  const std::vector<std::size_t> chosen = internal::ChooseForBudget(
      s.candidates, s.samples, *s.grid, static_cast<std::size_t>(max_spheres), control);
  if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
  if (control.on_progress) control.on_progress(0.5);
  absl::StatusOr<GeneratedCover> out = Finish(chosen, Stage(control, 0.5, 1.0));
  if (!out.ok()) return out.status();
  if (control.on_progress) control.on_progress(1.0);
  out->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

absl::StatusOr<GeneratedCover> GenerateCover(const Solid& solid, const CoverParameters& parameters,
                                             const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckCoverParameters(parameters); !s.ok()) return s;
  if (!parameters.max_protrusion) {
    absl::StatusOr<PreparedCover> prepared =
        PreparedCover::Prepare(solid, parameters, Stage(control, 0.0, 0.2));
    if (!prepared.ok()) return prepared.status();
    if (control.on_progress) control.on_progress(0.2);
    absl::StatusOr<GeneratedCover> out = prepared->Generate(
        parameters.max_spheres.value_or(kDefaultMaxSpheres), Stage(control, 0.2, 1.0));
    if (!out.ok()) return out.status();
    out->seconds = SecondsSince(start);
    return out;
  }
  // The delta mode: the fewest spheres whose certified delta is within the bound, searched over
  // budgets. Candidates for a budget large enough that the farthest-first estimate reaches the
  // bound (4x more at a time while it does not), then budgets from the first the estimate says
  // is enough (the estimate is usually above what is certified), then fewer, predicted from
  // the ratio of the certified delta to the estimate.
  const double bound = *parameters.max_protrusion;
  CoverParameters budgeted = parameters;
  budgeted.max_protrusion.reset();
  std::optional<PreparedCover> prepared;
  std::vector<double> estimates;
  for (std::int64_t most = kDeltaModeFirstBudget;; most *= 4) {
    budgeted.max_spheres = std::min(most, kDeltaModeMaxBudget);
    absl::StatusOr<PreparedCover> made = PreparedCover::Prepare(solid, budgeted, control);
    if (!made.ok()) return made.status();
    if (bound <= made->margin()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "cover: max_protrusion ", bound, " is within the certificate's finest cell diagonal ",
          made->margin(), " (raise it, or refine the certificate's resolution)"));
    }
    prepared.emplace(*std::move(made));
    estimates = prepared->EstimatedDeltas(*budgeted.max_spheres);
    if (estimates.back() <= bound || *budgeted.max_spheres == kDeltaModeMaxBudget) break;
    if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
  }
  if (control.on_progress) control.on_progress(0.2);
  const std::int64_t most = *budgeted.max_spheres;
  std::int64_t hi = most;
  for (std::int64_t n = 1; n <= most; ++n) {
    if (estimates[static_cast<std::size_t>(n - 1)] <= bound) {
      hi = n;
      break;
    }
  }
  absl::StatusOr<GeneratedCover> out = absl::FailedPreconditionError("no attempt");
  double least = std::numeric_limits<double>::infinity();  // certified delta, any attempt
  // Tries a budget of n; true when its certified delta is within the bound.
  const auto attempt = [&](std::int64_t n) -> absl::StatusOr<bool> {
    absl::StatusOr<GeneratedCover> tried = prepared->Generate(n, control);
    if (!tried.ok()) return tried.status();
    least = std::min(least, tried->certificate.delta);
    if (tried->certificate.delta > bound) return false;
    if (!out.ok() || tried->set.size() < out->set.size()) out = *std::move(tried);
    return true;
  };
  // The certified delta over the estimate at the last budget tried, which predicts the next.
  double ratio = 1.0;
  const auto tried_ratio = [&](std::int64_t n) {
    const double estimate = estimates[static_cast<std::size_t>(n - 1)];
    if (estimate > 0.0 && std::isfinite(least)) ratio = least / estimate;
  };
  absl::StatusOr<bool> fits = attempt(hi);
  if (!fits.ok()) return fits.status();
  tried_ratio(hi);
  // Over the bound at the estimate: larger budgets, doubling, up to the candidates' budget.
  int attempts = 1;
  std::int64_t lo = 0;  // the largest budget known not to fit (0: none)
  while (!*fits && hi < most && attempts < kDeltaModeAttempts) {
    lo = hi;
    hi = std::min(most, 2 * hi);
    fits = attempt(hi);
    if (!fits.ok()) return fits.status();
    ++attempts;
  }
  if (!out.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat("cover: no certified cover within max_protrusion ", bound, " with up to ", hi,
                     " spheres; the least delta reached was ", least,
                     " (ask for a larger max_protrusion, or a sphere budget)"));
  }
  // Fewer: the budget whose estimate, scaled by the last certified ratio, just meets the bound
  // (a little below it), kept strictly between the budgets known not to fit and to fit.
  for (; attempts < kDeltaModeAttempts && hi - lo > 1; ++attempts) {
    if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
    std::int64_t next = hi - 1;
    for (std::int64_t n = lo + 1; n < hi; ++n) {
      if (estimates[static_cast<std::size_t>(n - 1)] * ratio <= kDeltaModeAim * bound) {
        next = n;
        break;
      }
    }
    const double before = least;
    least = std::numeric_limits<double>::infinity();
    absl::StatusOr<bool> next_fits = attempt(next);
    if (!next_fits.ok()) return next_fits.status();
    tried_ratio(next);
    least = std::min(least, before);
    (*next_fits ? hi : lo) = next;
    if (control.on_progress) control.on_progress(0.2 + 0.8 * (attempts + 1) / kDeltaModeAttempts);
  }
  if (control.on_progress) control.on_progress(1.0);
  out->seconds = SecondsSince(start);
  return out;
}

double PreparedCover::prepare_seconds() const { return state_->prepare_seconds; }

}  // namespace inscribe
