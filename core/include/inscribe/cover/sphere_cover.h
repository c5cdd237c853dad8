// Cover sets: spheres that provably contain the whole solid (cover_certificate.h), with a
// certified bound delta on how far they reach outside it.
//
// GenerateCover chooses internal balls and grows them. The candidates: from each of many
// boundary points (every vertex and area samples), balls centred on the inward normal at a
// ladder of depths up to the deepest, each with radius = the depth of its centre (so a ball
// grown to R protrudes at most R - depth). The choice: the fewest candidates that reach every
// boundary sample (and interior stand-ins) by growing at most a threshold t: a greedy set
// cover, with t searched down to the least that fits the budget (for max_protrusion: the
// fewest spheres whose certified delta fits, a search over budgets). Then every boundary
// triangle goes whole, or cut into pieces while that saves growth, to the chosen ball that
// needs the least growth to hold its corners, plus a margin of one finest certificate cell's
// diagonal; a ball is convex, so it then holds
// the piece and its margin, and every certificate cell meeting the boundary lies in one ball.
// The certificate then passes (failed cells, if any, grow the ball needing the least growth
// and it certifies again): the result is always certified. delta is about t plus the margin
// plus the growth the boundary between samples needs.
//
// A budget's cover is the best (least certified delta, then least summed protrusion, then
// fewest spheres) of several certified constructions (CoverConstructions): that choice; the
// minimum enclosing ball of the vertices; k-center clusters of the samples with an enclosing
// ball each; and, with CoverConstructions::monotone, the best cover of one sphere fewer, as it
// is and with its most protruding sphere split in two. The best is tightened: per sphere, the
// ball holding what it alone holds whose centre protrudes least (cover_constructions.h),
// certified again, while delta falls. A construction that does not certify is dropped. So one
// sphere is at most the enclosing ball (plus the certificate's margin), and a budget is no
// worse than each construction alone; with `monotone`, delta never rises with the budget up
// to kMonotoneCoverBudget. k-center, tightening and splitting to fill a budget run at budgets
// up to kMonotoneCoverBudget only (above, they cost a certificate per step and rarely win).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/solid.h"

namespace inscribe {

// Budgets up to which a cover at N is never worse than at N - 1 (it also tries the best cover
// at N - 1, and it with one sphere split): the counts planners give a link.
inline constexpr std::int64_t kMonotoneCoverBudget = 64;

// The certified constructions a budget's cover is the best of (each can be turned off, for
// comparisons; at least one of the first three must be on).
struct CoverConstructions {
  bool ladder = true;          // internal ladder balls chosen by a threshold search, grown
  bool enclosing_ball = true;  // one sphere: the minimum enclosing ball of the vertices
  bool k_center = true;        // farthest-point clusters of the samples, an enclosing ball each
  // Rounds of: per sphere, the enclosing ball of the boundary pieces and interior points it
  // alone holds (its centre moved toward that ball's where that protrudes less), certified.
  bool tighten = true;
  // Up to kMonotoneCoverBudget: also the best cover at N - 1 (made the same way, so
  // recursively) and that cover with its most protruding sphere split in two, the other
  // constructions only at 1..8, 11, 16, 23, 32, 45 and 64: delta never rises with N. Off by
  // default: a budget then costs about as many constructions as those budgets below it
  // (5-50x one construction), and between those budgets the split covers are looser than
  // the constructions made at the budget itself.
  bool monotone = false;
};

struct CoverParameters {
  // The two modes, at most one set: at most N spheres with the smallest delta reached (> 0),
  // or delta at most D mesh units with the fewest spheres (finite, > 0). Neither: at most
  // kDefaultMaxSpheres spheres.
  std::optional<std::int64_t> max_spheres;
  std::optional<double> max_protrusion;
  // Boundary points drawn (uniformly by area, fixed seed) that the choice must reach; every
  // mesh vertex is used too. 0..100,000,000; more: a tighter choice, slower.
  std::int64_t growth_samples = 20'000;
  // The certificate's settings. Every sphere reaches one finest cell's diagonal past the
  // boundary (so the certificate settles the cells there), which delta includes: a finer
  // resolution allows a smaller delta and costs more cells.
  CoverCertifyOptions certify;
  CoverConstructions constructions;
};

// OK, or INVALID_ARGUMENT naming the first bad field. O(1).
absl::Status CheckCoverParameters(const CoverParameters& parameters);

struct GeneratedCover {
  SphereSet set;                   // the cover (no contacts: its spheres touch nothing)
  CoverCertificate certificate;    // certified; delta is the cover's protrusion bound
  std::int64_t candidates = 0;     // balls the choice was made from
  std::int64_t grown_spheres = 0;  // spheres the repairs grew (after the first certificate)
  int repair_rounds = 0;           // certificates that failed before the one that passed
  double seconds = 0.0;            // all of it, the internal set included
  // Empty when the cover has as many spheres as the budget allowed; else why it has fewer
  // (no construction with more spheres certified a lower delta).
  std::string unused_reason;
};

// What GenerateCover chooses from, made once and asked for several budgets: the boundary
// samples, the candidate balls and their grid. For sharing one budget among many solids (a
// robot's links): estimate each solid's delta for every count, share, then generate each.
// Immutable and cheap to copy; `solid` must outlive it.
class PreparedCover {
 public:
  // `parameters` as GenerateCover takes them (max_protrusion ignored); max_spheres (default
  // kDefaultMaxSpheres) is the largest budget Generate will be asked for: it sets how many
  // candidates are made (8 ladder bases per sphere) and the boundary samples (40 per sphere,
  // 2,000 at least, CoverParameters::growth_samples at most). Errors as GenerateCover's.
  // Cost: the candidates' ladders, O(budget * log #T) closest-point queries, plus sampling.
  static absl::StatusOr<PreparedCover> Prepare(const Solid& solid,
                                               const CoverParameters& parameters,
                                               const GenerationControl& control = {});

  // Entry k-1: an estimate of the delta Generate(k) reaches, for k = 1..max_spheres: the
  // growth threshold of the farthest-first choice of k candidates plus the certificate's
  // margin. Non-increasing, and usually above what Generate certifies (its threshold search
  // ends near half the farthest-first one). O(max_spheres * (#samples + #candidates)).
  std::vector<double> EstimatedDeltas(std::int64_t max_spheres) const;

  // The budget mode: at most max_spheres (> 0) spheres, certified, the best of the
  // constructions (see above); fewer than max_spheres only with GeneratedCover::unused_reason
  // saying why. INVALID_ARGUMENT for a budget <= 0, CANCELLED. Deterministic: the covers for
  // budgets up to kMonotoneCoverBudget are remembered (each needs the one before it), which
  // changes no result, only the time of a later call. Safe to call from several threads.
  absl::StatusOr<GeneratedCover> Generate(std::int64_t max_spheres,
                                          const GenerationControl& control = {}) const;

  const Solid& solid() const;
  double margin() const;           // the certificate's cell diagonal every sphere reaches past
  double prepare_seconds() const;  // what Prepare took

 private:
  struct State;
  explicit PreparedCover(std::shared_ptr<const State> state);
  absl::StatusOr<GeneratedCover> Finish(std::vector<Sphere> spheres,
                                        const GenerationControl& control) const;
  absl::StatusOr<GeneratedCover> Construct(std::int64_t max_spheres,
                                           const GenerationControl& control) const;
  absl::StatusOr<GeneratedCover> Tighten(GeneratedCover cover,
                                         const GenerationControl& control) const;
  absl::StatusOr<GeneratedCover> SplitWorst(const GeneratedCover& cover,
                                            const GenerationControl& control) const;
  std::shared_ptr<const State> state_;
};

// A certified cover of `solid` (see above). INVALID_ARGUMENT for bad parameters, CANCELLED
// when control.cancel is set, FAILED_PRECONDITION when the solid has no volume to cover.
// Deterministic and parallel (TBB); progress goes to control.on_progress in [0, 1].
absl::StatusOr<GeneratedCover> GenerateCover(const Solid& solid, const CoverParameters& parameters,
                                             const GenerationControl& control = {});

}  // namespace inscribe
