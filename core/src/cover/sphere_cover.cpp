#include "inscribe/cover/sphere_cover.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "cover/cover_cells.h"
#include "cover/cover_choice.h"
#include "cover/cover_constructions.h"
#include "mesh/surface_sampling.h"

namespace inscribe {
namespace {

// Fixed, so that covers are reproducible.
constexpr std::uint64_t kGrowthSeed = 0x636f766572;  // "cover"
constexpr int kMaxRounds = 8;
// Rounds of holding a point the certificate found in no sphere, and of tightening.
constexpr int kWitnessRounds = 6;
constexpr int kTightenRounds = 2;
// The pieces that guide tightening and splitting are this many times coarser than the ones a
// cover holds (HoldBoundary holds the fine ones afterwards).
constexpr double kGuideEdge = 8.0;
// The compass search of a tightened sphere's centre: its first step (times the radius) and
// halvings.
constexpr double kCompassFirstStep = 0.25;
constexpr int kCompassHalvings = 5;
constexpr int kCompassMoves = 8;  // per step size
// Ladder bases per sphere of the budget (besides the vertices).
constexpr std::int64_t kBasesPerSphere = 8;
// The first rung of the ladders and the sample grid's cell, as fractions of the bounding
// box's largest side.
constexpr double kFirstRung = 1.0 / 256;
constexpr double kGridCell = 1.0 / 64;
// Growth a boundary piece held whole may cost beyond its best point, and the longest edge a
// piece is split to (both a fraction of the largest side).
constexpr double kBoundaryEdge = 1.0 / 1024;
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
    grown.radius = std::max(grown.radius, best_reach * (1.0 + internal::kReachMargin));
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
  const CoverConstructions& c = p.constructions;
  if (!c.ladder && !c.enclosing_ball && !c.k_center) {
    return absl::InvalidArgumentError(
        "cover: constructions turns off ladder, enclosing_ball and k_center: turn one on");
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
  // The covers made for budgets up to kMonotoneCoverBudget (each a function of its budget
  // alone, so remembering them changes no result).
  mutable std::mutex memo_mutex;
  mutable std::map<std::int64_t, GeneratedCover> memo;
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
  std::vector<internal::LadderBase> bases;
  const std::size_t stride = (sampled_vertices.size() + per_kind - 1) / per_kind;
  for (std::size_t i = 0; i < sampled_vertices.size(); i += stride) {
    bases.push_back({samples.points[i], sampled_vertices[i]});
  }
  for (Eigen::Index i = 0; i < std::min<Eigen::Index>(drawn.rows(), per_kind); ++i) {
    bases.push_back({drawn.row(i).transpose(), -1});
  }
  state->candidates = internal::LadderCandidates(solid, bases, state->scale * kFirstRung,
                                                 state->scale / 2, &state->interior);
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

namespace {

// Keeps the better of `best` and `tried`; a construction that failed (not certified, not
// certifiable) is dropped, a cancellation passed on.
absl::Status Keep(absl::StatusOr<GeneratedCover> tried, std::optional<GeneratedCover>* best) {
  if (!tried.ok()) {
    return tried.status().code() == absl::StatusCode::kCancelled ? tried.status()
                                                                 : absl::OkStatus();
  }
  if (!*best || internal::BetterCover(*tried, **best)) *best = *std::move(tried);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<GeneratedCover> PreparedCover::Finish(std::vector<Sphere> spheres,
                                                     const GenerationControl& stage) const {
  const State& s = *state_;
  GenerationControl quiet;
  quiet.cancel = stage.cancel;
  CoverCertifyOptions certify = s.parameters.certify;
  certify.stop_at_witness = true;
  // Every sphere holds its boundary pieces; a point of the solid the certificate finds in no
  // sphere is held too, by the sphere that grows least to reach it, and it certifies again.
  std::vector<Vector3> held_points = s.interior;
  for (int round = 0; round < kWitnessRounds; ++round) {
    std::vector<Sphere> held =
        internal::HoldBoundary(s.solid->mesh(), spheres, held_points, s.edge, s.margin);
    absl::StatusOr<CoverCertificate> certificate = CertifyCover(*s.solid, held, certify, quiet);
    if (!certificate.ok()) return certificate.status();
    if (!certificate->certified && certificate->uncovered_point) {
      held_points.push_back(*certificate->uncovered_point);
      continue;
    }
    GeneratedCover out;
    out.candidates = static_cast<std::int64_t>(s.candidates.size());
    if (!certificate->certified) {
      // Only cells too fine to settle are left (no point of the solid outside the spheres):
      // grow the spheres around them.
      const std::vector<Sphere> before = held;
      certificate = CertifyAndRepair(*s.solid, s.parameters, &held, &out.repair_rounds, quiet);
      if (!certificate.ok()) return certificate.status();
      for (std::size_t i = 0; i < held.size(); ++i) {
        out.grown_spheres += held[i].radius > before[i].radius;
      }
    }
    out.certificate = *std::move(certificate);
    out.set.spheres = std::move(held);
    return out;
  }
  return absl::FailedPreconditionError(
      absl::StrCat("cover: a construction left points of the solid uncovered after ",
                   kWitnessRounds, " rounds"));
}

absl::StatusOr<GeneratedCover> PreparedCover::Tighten(GeneratedCover cover,
                                                      const GenerationControl& control) const {
  const State& s = *state_;
  if (!s.parameters.constructions.tighten) return cover;
  for (int round = 0; round < kTightenRounds; ++round) {
    if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
    std::vector<Sphere> spheres = cover.set.spheres;
    const std::vector<std::vector<Vector3>> owned =
        internal::OwnedPoints(s.solid->mesh(), spheres, s.interior, kGuideEdge * s.edge);
    internal::ParallelFor(std::size_t{0}, spheres.size(), [&](std::size_t i) {
      if (owned[i].empty()) return;
      // The ball at centre c holding the part with the margin, and how far it protrudes.
      const auto ball_at = [&](const Vector3& c, double* protrusion) {
        double reach = 0.0;
        for (const Vector3& p : owned[i]) reach = std::max(reach, (p - c).norm());
        const Sphere ball{c, (reach + s.margin) * (1.0 + internal::kReachMargin)};
        *protrusion = ball.radius - internal::Depth(*s.solid, c);
        return ball;
      };
      // From the better of the sphere's own centre, its part's enclosing ball's and halfway, a
      // compass search: steps along the axes while one protrudes less, halved when none does.
      const Vector3 from = spheres[i].center, to = internal::EnclosingBall(owned[i]).center;
      double least = std::numeric_limits<double>::infinity();
      for (const double t : {0.0, 0.5, 1.0}) {
        double protrusion = 0.0;
        const Sphere ball = ball_at(from + t * (to - from), &protrusion);
        if (protrusion < least) {
          least = protrusion;
          spheres[i] = ball;
        }
      }
      double step = kCompassFirstStep * spheres[i].radius;
      for (int halving = 0; halving < kCompassHalvings; ++halving, step *= 0.5) {
        bool moved = true;
        for (int move = 0; moved && move < kCompassMoves; ++move) {
          moved = false;
          for (int axis = 0; axis < 6; ++axis) {
            Vector3 c = spheres[i].center;
            c[axis / 2] += axis % 2 == 0 ? step : -step;
            double protrusion = 0.0;
            const Sphere ball = ball_at(c, &protrusion);
            if (protrusion < least) {
              least = protrusion;
              spheres[i] = ball;
              moved = true;
            }
          }
        }
      }
    });
    absl::StatusOr<GeneratedCover> tighter = Finish(std::move(spheres), control);
    if (!tighter.ok()) {
      if (tighter.status().code() == absl::StatusCode::kCancelled) return tighter.status();
      break;
    }
    if (!internal::BetterCover(*tighter, cover)) break;
    cover = *std::move(tighter);
  }
  return cover;
}

absl::StatusOr<GeneratedCover> PreparedCover::SplitWorst(const GeneratedCover& cover,
                                                         const GenerationControl& control) const {
  const State& s = *state_;
  const std::vector<double>& protrusions = cover.certificate.protrusions;
  const auto worst = static_cast<std::size_t>(
      std::max_element(protrusions.begin(), protrusions.end()) - protrusions.begin());
  const std::vector<std::vector<Vector3>> owned =
      internal::OwnedPoints(s.solid->mesh(), cover.set.spheres, s.interior, kGuideEdge * s.edge);
  // A sphere holding nothing alone (or one point) has nothing to split.
  if (owned[worst].size() < 2) return absl::FailedPreconditionError("cover: nothing to split");
  const std::vector<Sphere> two = internal::KCenterBalls(owned[worst], 2);
  if (two.size() < 2) return absl::FailedPreconditionError("cover: nothing to split");
  std::vector<Sphere> spheres = cover.set.spheres;
  spheres[worst] = two[0];
  spheres.push_back(two[1]);
  return Finish(std::move(spheres), control);
}

absl::StatusOr<GeneratedCover> PreparedCover::Construct(std::int64_t max_spheres,
                                                        const GenerationControl& control) const {
  const State& s = *state_;
  const CoverConstructions& use = s.parameters.constructions;
  const auto budget = static_cast<std::size_t>(max_spheres);
  // Splitting to fill the budget, k-center and tightening at planner budgets only: above them
  // they cost a certificate per step and rarely win.
  const bool small = max_spheres <= kMonotoneCoverBudget;
  std::optional<GeneratedCover> best;
  if (use.ladder) {
    const std::vector<std::size_t> chosen =
        internal::ChooseForBudget(s.candidates, s.samples, *s.grid, budget, control);
    if (control.cancelled()) return absl::CancelledError("cover generation cancelled");
    std::vector<Sphere> spheres;
    for (const std::size_t i : chosen) spheres.push_back(s.candidates[i]);
    absl::StatusOr<GeneratedCover> ladder = Finish(std::move(spheres), control);
    // Fewer than the budget: split the most protruding sphere while that lowers delta.
    while (small && ladder.ok() && ladder->set.size() < budget) {
      absl::StatusOr<GeneratedCover> split = SplitWorst(*ladder, control);
      if (!split.ok() || !internal::BetterCover(*split, *ladder)) break;
      ladder = *std::move(split);
    }
    if (absl::Status kept = Keep(std::move(ladder), &best); !kept.ok()) return kept;
  }
  // The enclosing ball at one sphere (larger budgets start from it when monotone).
  if (use.enclosing_ball && (max_spheres == 1 || !use.monotone)) {
    const Vertices& vertices = s.solid->mesh().vertices;
    std::vector<Vector3> points(static_cast<std::size_t>(vertices.rows()));
    for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
      points[static_cast<std::size_t>(v)] = vertices.row(v).transpose();
    }
    if (absl::Status kept = Keep(Finish({internal::EnclosingBall(points)}, control), &best);
        !kept.ok()) {
      return kept;
    }
  }
  if (use.k_center && small) {
    if (absl::Status kept =
            Keep(Finish(internal::KCenterBalls(s.samples.points, budget), control), &best);
        !kept.ok()) {
      return kept;
    }
  }
  if (!best) {
    return absl::InternalError(
        absl::StrCat("cover: no construction certified a cover with ", max_spheres, " spheres"));
  }
  return *std::move(best);
}

absl::StatusOr<GeneratedCover> PreparedCover::Generate(std::int64_t max_spheres,
                                                       const GenerationControl& control) const {
  const auto start = std::chrono::steady_clock::now();
  if (max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover: max_spheres must be positive, got ", max_spheres));
  }
  const State& s = *state_;
  const bool monotone = s.parameters.constructions.monotone && max_spheres <= kMonotoneCoverBudget;
  if (monotone) {
    const std::lock_guard<std::mutex> lock(s.memo_mutex);
    if (const auto found = s.memo.find(max_spheres); found != s.memo.end()) {
      GeneratedCover out = found->second;
      out.seconds = SecondsSince(start);
      return out;
    }
  }
  // Up to kMonotoneCoverBudget the constructions run at the budgets of ConstructionBudget
  // only; between them the cover grows from the one before by splitting.
  std::optional<GeneratedCover> best;
  if (!monotone || internal::ConstructionBudget(max_spheres)) {
    absl::StatusOr<GeneratedCover> made = Construct(max_spheres, control);
    if (!made.ok()) return made.status();
    best = *std::move(made);
  }
  std::optional<GeneratedCover> fewer;
  if (monotone && max_spheres > 1) {
    // The best cover of one sphere fewer (the same rule, so never worse than any before it),
    // and it with its most protruding sphere split.
    absl::StatusOr<GeneratedCover> made_fewer = Generate(max_spheres - 1, control);
    if (!made_fewer.ok()) return made_fewer.status();
    fewer = *std::move(made_fewer);
    // A cover carried from a smaller budget was split there already (the same split).
    if (fewer->set.size() == static_cast<std::size_t>(max_spheres - 1)) {
      if (absl::Status kept = Keep(SplitWorst(*fewer, control), &best); !kept.ok()) return kept;
    }
  }
  // The best construction tightened; then the cover of one sphere fewer if still better.
  if (best && max_spheres <= kMonotoneCoverBudget) {
    absl::StatusOr<GeneratedCover> tightened = Tighten(*std::move(best), control);
    if (!tightened.ok()) return tightened.status();
    best = *std::move(tightened);
  }
  if (fewer) {
    if (absl::Status kept = Keep(*std::move(fewer), &best); !kept.ok()) return kept;
  }
  GeneratedCover out = *std::move(best);
  out.unused_reason.clear();
  if (out.set.size() < static_cast<std::size_t>(max_spheres)) {
    out.unused_reason =
        max_spheres <= kMonotoneCoverBudget
            ? absl::StrCat("no construction with more than ", out.set.size(), " of the ",
                           max_spheres, " spheres allowed certified a lower delta (",
                           out.certificate.delta, ")")
            : absl::StrCat("the choice reached every sample with ", out.set.size(), " of the ",
                           max_spheres, " spheres allowed (more are not tried above ",
                           kMonotoneCoverBudget, ")");
  }
  if (monotone) {
    const std::lock_guard<std::mutex> lock(s.memo_mutex);
    s.memo.emplace(max_spheres, out);
  }
  if (control.on_progress) control.on_progress(1.0);
  out.seconds = SecondsSince(start);
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
