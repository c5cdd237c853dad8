#include "cover/cover_choice.h"

#include <algorithm>
#include <limits>
#include <queue>

#include "base/parallel.h"

namespace inscribe::internal {
namespace {

// Binary search steps on the threshold of the budget mode.
constexpr int kThresholdSteps = 10;
// The share of the farthest-first threshold the search tries first.
constexpr double kFirstListPart = 0.65;

// The farthest-first choice (Gonzalez): the deepest candidate, then repeatedly the candidate
// that reaches the worst-served sample with the least growth. Returns the chosen candidates
// and the growth that serves every sample (an upper bound for the threshold search).
// `thresholds`, when given, gets the growth serving every sample after each pick.
std::pair<std::vector<std::size_t>, double> FarthestFirst(
    const std::vector<Sphere>& candidates, const CoverSamples& samples, std::size_t count,
    std::vector<double>* thresholds = nullptr) {
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
    ParallelFor(std::size_t{0}, samples.points.size(), [&](std::size_t p) {
      served[p] = std::min(served[p], Growth(s, samples.points[p]));
    });
    const auto at = std::max_element(served.begin(), served.end());
    worst = *at;
    if (thresholds != nullptr) thresholds->push_back(std::max(worst, 0.0));
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

}  // namespace

std::vector<double> FarthestFirstThresholds(const std::vector<Sphere>& candidates,
                                            const CoverSamples& samples, std::size_t count) {
  std::vector<double> thresholds;
  FarthestFirst(candidates, samples, count, &thresholds);
  // Fewer picks than asked: every sample was reached, or every candidate taken.
  thresholds.resize(count, thresholds.empty() ? 0.0 : thresholds.back());
  return thresholds;
}

ReachLists MakeReachLists(const std::vector<Sphere>& candidates, const CoverSamples& samples,
                          const PointGrid& grid, double limit) {
  std::vector<std::vector<std::pair<float, std::int32_t>>> lists(candidates.size());
  ParallelFor(std::size_t{0}, candidates.size(), [&](std::size_t i) {
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
  ParallelFor(std::size_t{0}, candidates.size(), [&](std::size_t i) {
    for (std::size_t k = 0; k < lists[i].size(); ++k) {
      out.growth[out.begin[i] + k] = lists[i][k].first;
      out.sample[out.begin[i] + k] = lists[i][k].second;
    }
  });
  return out;
}

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

std::vector<std::size_t> ChooseForBudget(const std::vector<Sphere>& candidates,
                                         const CoverSamples& samples, const PointGrid& grid,
                                         std::size_t count, const GenerationControl& control) {
  auto [chosen, limit] = FarthestFirst(candidates, samples, count);
  if (chosen.size() < count || limit <= 0.0) return chosen;
  // The search usually ends near half the farthest-first threshold: lists up to a part of it
  // first (they grow with the threshold), the whole when nothing fits below that part.
  for (const double part : {kFirstListPart, 1.0}) {
    const ReachLists lists = MakeReachLists(candidates, samples, grid, part * limit);
    double lo = 0.0, hi = part * limit;
    bool found = part == 1.0;
    for (int step = 0; step < kThresholdSteps && !control.cancelled(); ++step) {
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

}  // namespace inscribe::internal
