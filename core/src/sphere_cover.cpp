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
constexpr double kGridCell = 1.0 / 64;
// Longest edge of the boundary's pieces each held whole by one sphere (a fraction of the
// largest side): a piece costs at most this much more growth than its best point.
constexpr double kBoundaryEdge = 1.0 / 1024;
// Steps of the search for the deepest centre on a normal (each shrinks the interval by 0.618).
constexpr int kGoldenSteps = 10;
// Thresholds the delta mode tries.
constexpr int kDeltaModeAttempts = 5;
// Binary search steps on the threshold of the budget mode.
constexpr int kThresholdSteps = 10;
// The share of the farthest-first threshold the search tries first.
constexpr double kFirstListPart = 0.65;

// How much candidate i must grow to reach sample p: |p - c_i| - r_i.
double Growth(const Sphere& s, const Vector3& p) { return (p - s.center).norm() - s.radius; }

// The points a cover must reach: the mesh vertices, boundary samples, and the deepest
// candidate centres (standing in for the interior).
struct Samples {
  std::vector<Vector3> points;
};

// Uniform grid over points, for the points within a distance of a centre.
class PointGrid {
 public:
  PointGrid(const std::vector<Vector3>& points, double cell) : points_(points), cell_(cell) {
    lo_ = hi_ = points.empty() ? Vector3::Zero() : points[0];
    for (const Vector3& p : points) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
    for (int k = 0; k < 3; ++k) {
      dims_[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi_[k] - lo_[k]) / cell) + 1);
    }
    std::vector<std::int64_t> key(points.size());
    start_.assign(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]) + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      key[i] = Key(Cell(points[i]));
      ++start_[static_cast<std::size_t>(key[i]) + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    order_.resize(points.size());
    std::vector<std::int64_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      order_[static_cast<std::size_t>(fill[static_cast<std::size_t>(key[i])]++)] =
          static_cast<std::int32_t>(i);
    }
  }

  // Calls f(index) for every point within `radius` of `center` (and maybe a few more).
  template <typename F>
  void ForEachNear(const Vector3& center, double radius, F&& f) const {
    const Eigen::Array3i a = Cell(center - Vector3::Constant(radius));
    const Eigen::Array3i b = Cell(center + Vector3::Constant(radius));
    for (int x = a[0]; x <= b[0]; ++x) {
      for (int y = a[1]; y <= b[1]; ++y) {
        for (int z = a[2]; z <= b[2]; ++z) {
          const std::int64_t k = Key(Eigen::Array3i(x, y, z));
          for (std::int64_t j = start_[static_cast<std::size_t>(k)];
               j < start_[static_cast<std::size_t>(k) + 1]; ++j) {
            f(static_cast<std::size_t>(order_[static_cast<std::size_t>(j)]));
          }
        }
      }
    }
  }

 private:
  Eigen::Array3i Cell(const Vector3& p) const {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k) {
      const double v = std::floor((p[k] - lo_[k]) / cell_);
      c[k] = static_cast<int>(std::clamp(v, 0.0, static_cast<double>(dims_[k] - 1)));
    }
    return c;
  }
  std::int64_t Key(const Eigen::Array3i& c) const {
    return (static_cast<std::int64_t>(c[0]) * dims_[1] + c[1]) * dims_[2] + c[2];
  }

  const std::vector<Vector3>& points_;
  double cell_;
  Vector3 lo_, hi_;
  std::int64_t dims_[3] = {1, 1, 1};
  std::vector<std::int64_t> start_;
  std::vector<std::int32_t> order_;
};

// For each candidate, the samples it reaches by growing at most `limit`, sorted by growth:
// the candidate's cover set at any threshold t <= limit is a prefix.
struct ReachLists {
  std::vector<std::size_t> begin;  // candidate i: entries [begin[i], begin[i + 1])
  std::vector<float> growth;       // rounded; only orders and thresholds the choice
  std::vector<std::int32_t> sample;

  std::size_t Prefix(std::size_t i, double t) const {
    const auto first = growth.begin() + static_cast<std::ptrdiff_t>(begin[i]);
    const auto last = growth.begin() + static_cast<std::ptrdiff_t>(begin[i + 1]);
    return static_cast<std::size_t>(std::upper_bound(first, last, static_cast<float>(t)) - first);
  }
};

ReachLists MakeReachLists(const std::vector<Sphere>& candidates, const Samples& samples,
                          const PointGrid& grid, double limit) {
  std::vector<std::vector<std::pair<float, std::int32_t>>> lists(candidates.size());
  tbb::parallel_for(std::size_t{0}, candidates.size(), [&](std::size_t i) {
    std::vector<std::pair<float, std::int32_t>>& list = lists[i];
    grid.ForEachNear(candidates[i].center, candidates[i].radius + limit, [&](std::size_t p) {
      const double g = Growth(candidates[i], samples.points[p]);
      if (g <= limit) list.emplace_back(static_cast<float>(g), static_cast<std::int32_t>(p));
    });
    std::sort(list.begin(), list.end());
  });
  ReachLists out;
  out.begin.assign(candidates.size() + 1, 0);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    out.begin[i + 1] = out.begin[i] + lists[i].size();
  }
  out.growth.resize(out.begin.back());
  out.sample.resize(out.begin.back());
  tbb::parallel_for(std::size_t{0}, candidates.size(), [&](std::size_t i) {
    for (std::size_t k = 0; k < lists[i].size(); ++k) {
      out.growth[out.begin[i] + k] = lists[i][k].first;
      out.sample[out.begin[i] + k] = lists[i][k].second;
    }
  });
  return out;
}

// The farthest-first choice (Gonzalez): the deepest candidate, then repeatedly the candidate
// that reaches the worst-served sample with the least growth. Returns the chosen candidates
// and the growth that serves every sample (an upper bound for the threshold search).
std::pair<std::vector<std::size_t>, double> FarthestFirst(const std::vector<Sphere>& candidates,
                                                          const Samples& samples,
                                                          std::size_t count) {
  std::vector<double> served(samples.points.size(), std::numeric_limits<double>::infinity());
  std::vector<char> taken(candidates.size(), 0);
  std::vector<std::size_t> chosen;
  std::size_t next = 0;
  for (std::size_t i = 1; i < candidates.size(); ++i) {
    if (candidates[i].radius > candidates[next].radius) next = i;
  }
  double worst = std::numeric_limits<double>::infinity();
  while (true) {
    chosen.push_back(next);
    taken[next] = 1;
    const Sphere& s = candidates[next];
    tbb::parallel_for(std::size_t{0}, samples.points.size(), [&](std::size_t p) {
      served[p] = std::min(served[p], Growth(s, samples.points[p]));
    });
    const auto at = std::max_element(served.begin(), served.end());
    worst = *at;
    if (chosen.size() == count || worst <= 0.0 || chosen.size() == candidates.size()) break;
    const Vector3& p = samples.points[static_cast<std::size_t>(at - served.begin())];
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (taken[i]) continue;
      const double g = Growth(candidates[i], p);
      if (g < best) {
        best = g;
        next = i;
      }
    }
  }
  return {std::move(chosen), std::max(worst, 0.0)};
}

// Greedy set cover at threshold t: repeatedly the candidate reaching the most samples not yet
// reached (ties: the lower index), lazily re-counted. The chosen candidates, or nothing when
// more than `limit` are needed or some sample is out of every candidate's reach.
std::optional<std::vector<std::size_t>> GreedyCover(const ReachLists& lists,
                                                    std::size_t num_samples, double t,
                                                    std::size_t limit) {
  const std::size_t n = lists.begin.size() - 1;
  std::vector<std::size_t> prefix(n);
  std::priority_queue<std::pair<std::size_t, std::int64_t>> queue;  // (gain, -index)
  std::vector<char> reachable(num_samples, 0);
  for (std::size_t i = 0; i < n; ++i) {
    prefix[i] = lists.Prefix(i, t);
    for (std::size_t k = 0; k < prefix[i]; ++k) reachable[lists.sample[lists.begin[i] + k]] = 1;
    if (prefix[i] > 0) queue.emplace(prefix[i], -static_cast<std::int64_t>(i));
  }
  if (std::find(reachable.begin(), reachable.end(), 0) != reachable.end()) return std::nullopt;
  std::vector<char> reached(num_samples, 0);
  std::size_t left = num_samples;
  std::vector<std::size_t> chosen;
  while (left > 0) {
    if (queue.empty()) return std::nullopt;
    const auto [gain, negative] = queue.top();
    queue.pop();
    const auto i = static_cast<std::size_t>(-negative);
    std::size_t fresh = 0;
    for (std::size_t k = 0; k < prefix[i]; ++k) fresh += !reached[lists.sample[lists.begin[i] + k]];
    if (fresh == 0) continue;
    if (fresh < gain) {
      queue.emplace(fresh, negative);
      continue;
    }
    if (chosen.size() == limit) return std::nullopt;
    chosen.push_back(i);
    for (std::size_t k = 0; k < prefix[i]; ++k) {
      char& r = reached[lists.sample[lists.begin[i] + k]];
      left -= !r;
      r = 1;
    }
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

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

bool Cancelled(const GenerationControl& control) {
  return control.cancel != nullptr && control.cancel->load();
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
    double last = 0.0, last_s = 0.0, before_s = 0.0;
    int k = 0;
    for (; k < ladder; ++k) {
      const double s = s0 * std::pow(factor, k);
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
    double lo = before_s, hi = k < ladder ? s0 * std::pow(factor, k) : last_s;
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

// The budget mode's choice: at most `count` candidates reaching every sample with the least
// growth threshold found (a binary search over greedy set covers, from the farthest-first
// choice's threshold down).
std::vector<std::size_t> ChooseForBudget(const std::vector<Sphere>& candidates,
                                         const Samples& samples, const PointGrid& grid,
                                         std::size_t count, const GenerationControl& control) {
  auto [chosen, limit] = FarthestFirst(candidates, samples, count);
  if (chosen.size() < count || limit <= 0.0) return chosen;
  // The search usually ends near half the farthest-first threshold: lists up to a part of it
  // first (they grow with the threshold), the whole when nothing fits below that part.
  for (const double part : {kFirstListPart, 1.0}) {
    const ReachLists lists = MakeReachLists(candidates, samples, grid, part * limit);
    double lo = 0.0, hi = part * limit;
    bool found = part == 1.0;
    for (int step = 0; step < kThresholdSteps && !Cancelled(control); ++step) {
      const double t = step == 0 && !found ? hi : 0.5 * (lo + hi);
      if (std::optional<std::vector<std::size_t>> cover =
              GreedyCover(lists, samples.points.size(), t, count)) {
        chosen = *std::move(cover);
        hi = t;
        found = true;
      } else if (!found) {
        break;  // nothing fits within this part
      } else {
        lo = t;
      }
    }
    if (found) break;
  }
  return chosen;
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
  Samples samples;
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
  const PointGrid grid(samples.points, scale * kGridCell);
  if (Cancelled(control)) return absl::CancelledError("cover generation cancelled");
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
    const std::vector<std::size_t> chosen =
        ChooseForBudget(candidates, samples, grid, static_cast<std::size_t>(budget), control);
    if (Cancelled(control)) return absl::CancelledError("cover generation cancelled");
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
      if (Cancelled(control)) return absl::CancelledError("cover generation cancelled");
      const ReachLists lists = MakeReachLists(candidates, samples, grid, t);
      const std::optional<std::vector<std::size_t>> chosen =
          GreedyCover(lists, samples.points.size(), t, candidates.size());
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
