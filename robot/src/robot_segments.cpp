// RobotStateChecker's segment checks and travel bounds (robot_states.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/robot_states.h"
#include "robot_state_model.h"

namespace inscribe::robot {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Model = RobotStateChecker::Model;

absl::Status CheckConfiguration(const Model& model, absl::Span<const double> q, const char* name) {
  const std::size_t v = model.kinematics.variables().size();
  if (q.size() != v) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " has ", q.size(), " values; the robot has ", v, " variables"));
  }
  for (std::size_t i = 0; i < v; ++i) {
    if (!std::isfinite(q[i])) {
      return absl::InvalidArgumentError(absl::StrCat(name, " value ", i, " is not finite"));
    }
  }
  return absl::OkStatus();
}

std::vector<double> TravelBounds(const Model& model, absl::Span<const double> q0,
                                 absl::Span<const double> q1) {
  const Kinematics& k = model.kinematics;
  std::vector<double> bounds(model.local.size());
  const double margin = RobotMargin(model);
  for (std::size_t i = 0; i < model.local.size(); ++i) {
    double arm = model.local[i].norm();  // bounds |centre| in the current link's frame
    double travel = 0.0;
    for (int link = model.links[model.sphere_link[i]].link; k.parent(link) >= 0;
         link = k.parent(link)) {
      const Model::JointBound& joint = model.joints[link];
      double delta = 0.0, extent = 0.0;
      if (joint.variable >= 0) {
        const double v0 = joint.multiplier * q0[joint.variable] + joint.offset;
        const double v1 = joint.multiplier * q1[joint.variable] + joint.offset;
        delta = std::abs(v1 - v0);
        extent = std::max(std::abs(v0), std::abs(v1));
      }
      switch (joint.type) {
        case UrdfJointType::kRevolute:
        case UrdfJointType::kContinuous:
          travel += delta * (arm + joint.anchor);  // |centre - a point of the axis|
          arm += joint.origin + 2.0 * joint.anchor;
          break;
        case UrdfJointType::kPrismatic:
          travel += delta;  // the axis is a unit vector
          arm += joint.origin + extent;
          break;
        default:  // no motion: fixed, and floating and planar joints at their origins
          arm += joint.origin + 2.0 * joint.anchor;
          break;
      }
    }
    bounds[i] = travel * (1.0 + 1e-12) + margin;
  }
  return bounds;
}

// What a sub-segment's end contributes: per sphere a lower bound of its clearance (at least
// up to the clearance the segment needs), per self pair a lower bound of its distance, and
// whether the state collides.
struct EndBounds {
  std::vector<double> sphere;
  std::vector<double> pair;
  bool collides = false;
};

}  // namespace

absl::StatusOr<std::vector<double>> RobotStateChecker::SegmentTravelBounds(
    absl::Span<const double> q0, absl::Span<const double> q1) const {
  if (absl::Status status = CheckConfiguration(*model_, q0, "q0"); !status.ok()) return status;
  if (absl::Status status = CheckConfiguration(*model_, q1, "q1"); !status.ok()) return status;
  return TravelBounds(*model_, q0, q1);
}

absl::StatusOr<SegmentResult> RobotStateChecker::CheckSegment(absl::Span<const double> q0,
                                                              absl::Span<const double> q1,
                                                              const Environment& environment,
                                                              const SegmentOptions& options) const {
  const Model& model = *model_;
  if (absl::Status status = CheckConfiguration(model, q0, "q0"); !status.ok()) return status;
  if (absl::Status status = CheckConfiguration(model, q1, "q1"); !status.ok()) return status;
  const std::size_t v = q0.size();
  auto at = [&](double t) {
    std::vector<double> q(v);
    for (std::size_t j = 0; j < v; ++j) q[j] = q0[j] + t * (q1[j] - q0[j]);
    return q;
  };
  SegmentResult result;
  if (options.method == SegmentOptions::Method::kResolution) {
    if (!(options.resolution > 0.0) || !std::isfinite(options.resolution)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "resolution ", options.resolution, " must be finite and > 0 (radians or metres)"));
    }
    double longest = 0.0;
    for (std::size_t j = 0; j < v; ++j) longest = std::max(longest, std::abs(q1[j] - q0[j]));
    const std::int64_t steps = std::max<std::int64_t>(
        1, static_cast<std::int64_t>(std::ceil(longest / options.resolution)));
    for (std::int64_t i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      absl::StatusOr<StateBatchResult> state = CheckStates(at(t), environment);
      if (!state.ok()) return state.status();
      ++result.states_checked;
      if (state->collides[0]) {
        result.collides = true;
        result.t_collision = t;
        return result;
      }
    }
    return result;
  }
  if (!(options.min_step > 0.0 && options.min_step <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_step ", options.min_step, " must be in (0, 1]"));
  }
  const std::vector<double> travel = TravelBounds(model, q0, q1);
  const double lipschitz = environment.Lipschitz();
  std::vector<double> link_travel(model.links.size(), 0.0);
  for (std::size_t i = 0; i < travel.size(); ++i) {
    link_travel[model.sphere_link[i]] = std::max(link_travel[model.sphere_link[i]], travel[i]);
  }
  PosedState state;
  std::vector<ClearanceInterval> fast(model.local.size());
  auto evaluate = [&](double t) -> absl::StatusOr<EndBounds> {
    const std::vector<double> q = at(t);
    if (absl::Status status = PoseState(model, q, &state); !status.ok()) return status;
    ++result.states_checked;
    EndBounds end;
    end.sphere.resize(model.local.size());
    environment.Clearances(state.world, {kInf, kInf}, absl::MakeSpan(fast));
    for (std::size_t i = 0; i < fast.size(); ++i) {
      ClearanceInterval interval = fast[i];
      const double needed = lipschitz * travel[i];
      // Tighten up to twice what the segment needs, plus 1 nm: an answer "beyond
      // max_distance" is max_distance less the margin, which must still exceed `needed`.
      if (interval.lower <= needed) {
        const ClearanceRequest request{0.0, 2.0 * needed + 1e-9};
        environment.Clearances(absl::MakeConstSpan(&state.world[i], 1), request,
                               absl::MakeSpan(&interval, 1));
      }
      end.sphere[i] = interval.lower;
      if (!interval.clear() && !end.collides) {
        end.collides = interval.upper <= 0.0 ||
                       environment.FirstColliding(absl::MakeConstSpan(&state.world[i], 1)) >= 0;
      }
    }
    end.pair.resize(model.self_pairs.size());
    for (std::size_t p = 0; p < model.self_pairs.size(); ++p) {
      double distance = 0.0;
      if (LinksCollide(model, &state, model.self_pairs[p].first, model.self_pairs[p].second,
                       &distance)) {
        end.collides = true;
      }
      end.pair[p] = distance - RobotMargin(model);
    }
    return end;
  };
  auto covered = [&](const EndBounds& a, const EndBounds& b, double span) {
    for (std::size_t i = 0; i < travel.size(); ++i) {
      if (!(a.sphere[i] + b.sphere[i] > span * lipschitz * travel[i])) return false;
    }
    for (std::size_t p = 0; p < model.self_pairs.size(); ++p) {
      const double moved =
          link_travel[model.self_pairs[p].first] + link_travel[model.self_pairs[p].second];
      if (!(a.pair[p] + b.pair[p] > span * moved)) return false;
    }
    return true;
  };
  struct Piece {
    double t0, t1;
    EndBounds a, b;
  };
  absl::StatusOr<EndBounds> start = evaluate(0.0);
  if (!start.ok()) return start.status();
  if (start->collides) {
    result.collides = true;
    result.t_collision = 0.0;
    return result;
  }
  absl::StatusOr<EndBounds> finish = evaluate(1.0);
  if (!finish.ok()) return finish.status();
  if (finish->collides) {
    result.collides = true;
    result.t_collision = 1.0;
    return result;
  }
  bool proved = true;
  std::vector<Piece> stack;
  stack.push_back({0.0, 1.0, *std::move(start), *std::move(finish)});
  while (!stack.empty()) {
    Piece piece = std::move(stack.back());
    stack.pop_back();
    const double span = piece.t1 - piece.t0;
    if (covered(piece.a, piece.b, span)) continue;
    if (span < options.min_step) {
      proved = false;
      continue;
    }
    const double mid = 0.5 * (piece.t0 + piece.t1);
    absl::StatusOr<EndBounds> middle = evaluate(mid);
    if (!middle.ok()) return middle.status();
    if (middle->collides) {
      result.collides = true;
      result.t_collision = mid;
      return result;
    }
    // Left half on top: the earlier half is searched first.
    stack.push_back({mid, piece.t1, *middle, std::move(piece.b)});
    stack.push_back({piece.t0, mid, std::move(piece.a), *std::move(middle)});
  }
  result.proved = proved;
  return result;
}

}  // namespace inscribe::robot
