#include "inscribe/robot/robot_states.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/distance/certified_distance.h"
#include "robot_state_model.h"

namespace inscribe::robot {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using Model = RobotStateChecker::Model;

double Buffer(const std::map<std::string, double>& buffers, const std::string& link) {
  const auto found = buffers.find(link);
  return found == buffers.end() ? 0.0 : found->second;
}

// A sphere's last query: its centre then and the interval it got.
struct Certificate {
  Vector3 centre = Vector3::Zero();
  ClearanceInterval interval;
  bool valid = false;
};

// The certificate's interval at `centre`: widened by L times the distance moved.
ClearanceInterval Widened(const Certificate& certificate, const Vector3& centre, double lipschitz,
                          double margin) {
  const double moved = (centre - certificate.centre).norm() + margin;
  return {certificate.interval.lower - lipschitz * moved - margin,
          certificate.interval.upper + lipschitz * moved + margin};
}

ClearanceInterval Intersect(const ClearanceInterval& a, const ClearanceInterval& b) {
  return {std::max(a.lower, b.lower), std::min(a.upper, b.upper)};
}

bool Answers(const ClearanceInterval& interval, const ClearanceRequest& request) {
  return interval.upper - interval.lower <= request.tolerance ||
         interval.lower >= request.max_distance;
}

}  // namespace

double RobotMargin(const Model& model) {
  return kEnvironmentMargin * model.scale + kCertifiedDistanceFloor;
}

absl::Status PoseLinks(const Model& model, absl::Span<const double> q, PosedState* state) {
  if (absl::Status status = model.kinematics.LinkPoses(q, &state->poses); !status.ok()) {
    return status;
  }
  const std::size_t n = model.local.size();
  state->world.resize(n);
  state->centres.resize(n);
  state->link_posed.assign(model.links.size(), 0);
  state->bound_centres.resize(model.links.size());
  for (std::size_t k = 0; k < model.links.size(); ++k) {
    state->bound_centres[k] = state->poses[model.links[k].link] * model.links[k].bound_centre;
  }
  return absl::OkStatus();
}

void PoseLinkSpheres(const Model& model, int k, PosedState* state) {
  if (state->link_posed[k]) return;
  state->link_posed[k] = 1;
  const Model::LinkSpheresRange& link = model.links[k];
  const Eigen::Isometry3d& pose = state->poses[link.link];
  for (int i = link.begin; i < link.end; ++i) {
    state->centres[i] = pose * model.local[i];
    state->world[i] = {state->centres[i], model.world_radius[i]};
  }
}

absl::Status PoseState(const Model& model, absl::Span<const double> q, PosedState* state) {
  if (absl::Status status = PoseLinks(model, q, state); !status.ok()) return status;
  for (int k = 0; k < static_cast<int>(model.links.size()); ++k) PoseLinkSpheres(model, k, state);
  return absl::OkStatus();
}

bool LinksCollide(const Model& model, PosedState* posed, int a, int b, double* distance) {
  const Model::LinkSpheresRange& la = model.links[a];
  const Model::LinkSpheresRange& lb = model.links[b];
  const double margin = RobotMargin(model);
  if (distance == nullptr) {
    const Vector3& ca = posed->bound_centres[a];
    const Vector3& cb = posed->bound_centres[b];
    const double reach = la.bound_self + lb.bound_self + margin;
    if ((ca - cb).squaredNorm() > reach * reach) return false;
  }
  PoseLinkSpheres(model, a, posed);
  PoseLinkSpheres(model, b, posed);
  const PosedState& state = *posed;
  const Vector3& cb = state.bound_centres[b];
  bool collide = false;
  double best = kInf;
  for (int i = la.begin; i < la.end; ++i) {
    // A row of a's spheres that cannot reach b's bounding ball is skipped (yes/no only).
    if (distance == nullptr) {
      const double row = model.self_radius[i] + lb.bound_self + margin;
      if ((state.centres[i] - cb).squaredNorm() > row * row) continue;
    }
    for (int j = lb.begin; j < lb.end; ++j) {
      const double d2 = (state.centres[i] - state.centres[j]).squaredNorm();
      const double reach = model.self_radius[i] + model.self_radius[j];
      if (distance != nullptr) {
        best = std::min(best, std::sqrt(d2) - reach);
      } else if (d2 <= (reach + margin) * (reach + margin)) {
        return true;
      }
    }
  }
  if (distance != nullptr) {
    *distance = best;
    collide = best <= margin;
  }
  return collide;
}

RobotStateChecker::RobotStateChecker(std::shared_ptr<const Model> model)
    : model_(std::move(model)) {}

absl::StatusOr<RobotStateChecker> RobotStateChecker::Create(const UrdfRobot& robot,
                                                            const RobotSpheres& spheres) {
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  if (!kinematics.ok()) return kinematics.status();
  if (absl::Status status = CheckRobotSpheres(spheres); !status.ok()) return status;
  auto model = std::make_shared<Model>(*std::move(kinematics));
  const Kinematics& k = model->kinematics;
  std::map<std::string, int> link_index;
  for (int link = 0; link < k.links(); ++link) link_index[k.link_name(link)] = link;
  std::map<std::string, int> checked;
  double largest_local = 0.0;
  for (const LinkSpheres& link : spheres.links) {
    const auto found = link_index.find(link.link);
    if (found == link_index.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("the sphere model's link '", link.link, "' is not a link of the robot"));
    }
    if (link.spheres.empty()) continue;
    const double world_buffer = Buffer(spheres.collision_buffer, link.link);
    const double self_buffer = Buffer(spheres.self_collision_buffer, link.link);
    Model::LinkSpheresRange range;
    range.link = found->second;
    range.begin = static_cast<int>(model->local.size());
    Vector3 lo = link.spheres[0].center, hi = lo;
    for (std::size_t s = 0; s < link.spheres.size(); ++s) {
      const Sphere& sphere = link.spheres[s];
      const double world = sphere.radius + world_buffer, self = sphere.radius + self_buffer;
      if (world < 0.0 || self < 0.0) {
        return absl::InvalidArgumentError(absl::StrCat(
            "link '", link.link, "' sphere ", s, ": radius ", sphere.radius, " with buffer ",
            world < 0.0 ? world_buffer : self_buffer, " is below 0 (a smaller negative buffer)"));
      }
      model->local.push_back(sphere.center);
      model->world_radius.push_back(world);
      model->self_radius.push_back(self);
      model->sphere_link.push_back(static_cast<int>(model->links.size()));
      lo = lo.cwiseMin(sphere.center);
      hi = hi.cwiseMax(sphere.center);
      largest_local = std::max(largest_local, sphere.center.norm() + std::max(world, self));
    }
    range.end = static_cast<int>(model->local.size());
    range.bound_centre = 0.5 * (lo + hi);
    for (int i = range.begin; i < range.end; ++i) {
      const double from = (model->local[i] - range.bound_centre).norm();
      range.bound_world = std::max(range.bound_world, from + model->world_radius[i]);
      range.bound_self = std::max(range.bound_self, from + model->self_radius[i]);
    }
    // Room for the rounding of the norms above.
    range.bound_world *= 1.0 + 1e-12;
    range.bound_self *= 1.0 + 1e-12;
    checked[link.link] = static_cast<int>(model->links.size());
    model->links.push_back(range);
    model->link_names.push_back(link.link);
  }
  if (model->links.empty()) {
    return absl::InvalidArgumentError("the sphere model has no spheres on the robot's links");
  }
  for (int a = 0; a < static_cast<int>(model->links.size()); ++a) {
    for (int b = a + 1; b < static_cast<int>(model->links.size()); ++b) {
      std::pair<std::string, std::string> key(model->link_names[a], model->link_names[b]);
      if (key.second < key.first) std::swap(key.first, key.second);
      if (spheres.self_collision_ignore.count(key) == 0) model->self_pairs.emplace_back(a, b);
    }
  }
  model->joints.resize(k.links());
  double reach = 0.0;
  for (int link = 0; link < k.links(); ++link) {
    const int j = k.parent_joint(link);
    if (j < 0) continue;
    const UrdfJoint& joint = robot.joints[j];
    const Kinematics::JointDrive drive = k.drive(link);
    Model::JointBound& bound = model->joints[link];
    bound.type = joint.type;
    bound.variable = drive.variable;
    bound.multiplier = drive.multiplier;
    bound.offset = drive.offset;
    bound.origin = joint.origin.xyz.norm();
    bound.anchor = joint.anchor.norm();
    reach += bound.origin + 2.0 * bound.anchor;
    if (joint.type == UrdfJointType::kPrismatic) {
      reach += std::abs(drive.multiplier) * std::max(std::abs(joint.lower), std::abs(joint.upper)) +
               std::abs(drive.offset);
    }
  }
  model->scale = reach + largest_local;
  return RobotStateChecker(std::move(model));
}

const Kinematics& RobotStateChecker::kinematics() const { return model_->kinematics; }
int RobotStateChecker::variables() const {
  return static_cast<int>(model_->kinematics.variables().size());
}
const std::vector<std::string>& RobotStateChecker::links() const { return model_->link_names; }
int RobotStateChecker::spheres() const { return static_cast<int>(model_->local.size()); }
const std::vector<std::pair<int, int>>& RobotStateChecker::self_pairs() const {
  return model_->self_pairs;
}

absl::StatusOr<std::vector<Sphere>> RobotStateChecker::WorldSpheres(absl::Span<const double> q,
                                                                    double extra) const {
  PosedState state;
  if (absl::Status status = PoseState(*model_, q, &state); !status.ok()) return status;
  for (Sphere& sphere : state.world) sphere.radius += extra;
  return state.world;
}

absl::StatusOr<StateBatchResult> RobotStateChecker::CheckStates(absl::Span<const double> states,
                                                                const Environment& environment,
                                                                const StateQuery& query) const {
  const Model& model = *model_;
  const std::size_t v = model.kinematics.variables().size();
  if (v == 0 ? !states.empty() : states.size() % v != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "states has ", states.size(), " values, not a multiple of the robot's ", v, " variables"));
  }
  if (absl::Status status = CheckClearanceRequest(query.clearance); !status.ok()) return status;
  const int count = v == 0 ? 0 : static_cast<int>(states.size() / v);
  const int links = static_cast<int>(model.links.size());
  const int spheres = static_cast<int>(model.local.size());
  StateBatchResult result;
  result.states = count;
  result.links = links;
  result.spheres = spheres;
  result.collides.assign(count, 0);
  result.world_collision.assign(count, 0);
  result.self_collision.assign(count, 0);
  if (query.intervals) result.link_clearance.resize(static_cast<std::size_t>(count) * links);
  if (query.intervals && query.per_sphere) {
    result.sphere_clearance.resize(static_cast<std::size_t>(count) * spheres);
  }
  const double lipschitz = environment.Lipschitz();
  const double margin = RobotMargin(model);
  const ClearanceRequest fast{kInf, kInf};
  PosedState state;
  std::vector<Certificate> certificates(query.reuse_certificates ? spheres : 0);
  std::vector<ClearanceInterval> intervals(spheres);
  std::vector<std::uint8_t> refined(spheres);
  std::vector<Sphere> pending;
  std::vector<int> pending_index;
  std::vector<ClearanceInterval> pending_out;

  // One sphere's interval from the environment, kept as its certificate.
  auto ask = [&](int i, const ClearanceRequest& request) {
    ClearanceInterval out;
    environment.Clearances(absl::MakeConstSpan(&state.world[i], 1), request,
                           absl::MakeSpan(&out, 1));
    ++result.ball_queries;
    if (query.reuse_certificates) {
      Certificate& c = certificates[i];
      if (c.valid) out = Intersect(out, Widened(c, state.centres[i], lipschitz, margin));
      c = {state.centres[i], out, true};
    }
    return out;
  };
  // Whether sphere i, whose interval is `interval`, collides (exactly, up to the margin).
  auto collides = [&](int i, const ClearanceInterval& interval) {
    if (interval.clear()) return false;
    if (interval.upper <= 0.0) return true;
    ++result.ball_queries;
    return environment.FirstColliding(absl::MakeConstSpan(&state.world[i], 1)) >= 0;
  };
  auto self_collides = [&]() {
    for (const auto& [a, b] : model.self_pairs) {
      if (LinksCollide(model, &state, a, b, nullptr)) return true;
    }
    return false;
  };

  for (int s = 0; s < count; ++s) {
    // Yes/no without reuse poses a link's spheres only when its bounding ball is not clear.
    const bool lazy = !query.intervals && !query.reuse_certificates;
    const absl::Span<const double> q = states.subspan(s * v, v);
    if (absl::Status status = lazy ? PoseLinks(model, q, &state) : PoseState(model, q, &state);
        !status.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("state ", s, ": ", status.message()));
    }
    bool world = false;
    if (!query.intervals) {
      if (query.reuse_certificates) {
        for (int i = 0; i < spheres && !world; ++i) {
          const Certificate& c = certificates[i];
          if (c.valid && Widened(c, state.centres[i], lipschitz, margin).clear()) {
            ++result.reused;
            continue;
          }
          world = collides(i, ask(i, fast));
        }
      } else {
        for (int k = 0; k < links && !world; ++k) {
          const Model::LinkSpheresRange& link = model.links[k];
          // The bounding ball's O(1) bound only: an exact search over its larger reach would
          // cost more than the link's spheres.
          const Sphere bound{state.bound_centres[k], link.bound_world};
          ClearanceInterval bound_interval;
          environment.Clearances(absl::MakeConstSpan(&bound, 1), fast,
                                 absl::MakeSpan(&bound_interval, 1));
          ++result.ball_queries;
          if (bound_interval.clear()) continue;
          PoseLinkSpheres(model, k, &state);
          result.ball_queries += link.end - link.begin;
          world = environment.FirstColliding(absl::MakeConstSpan(state.world.data() + link.begin,
                                                                 link.end - link.begin)) >= 0;
        }
      }
    } else {
      // Every sphere's interval: a certificate's when it answers, else the O(1) one.
      pending.clear();
      pending_index.clear();
      for (int i = 0; i < spheres; ++i) {
        refined[i] = 0;
        if (query.reuse_certificates && certificates[i].valid) {
          const ClearanceInterval widened =
              Widened(certificates[i], state.centres[i], lipschitz, margin);
          if (Answers(widened, query.clearance)) {
            intervals[i] = widened;
            refined[i] = 1;
            ++result.reused;
            continue;
          }
        }
        pending.push_back(state.world[i]);
        pending_index.push_back(i);
      }
      pending_out.resize(pending.size());
      environment.Clearances(pending, fast, absl::MakeSpan(pending_out));
      result.ball_queries += static_cast<std::int64_t>(pending.size());
      for (std::size_t p = 0; p < pending.size(); ++p) {
        const int i = pending_index[p];
        ClearanceInterval out = pending_out[p];
        if (query.reuse_certificates) {
          Certificate& c = certificates[i];
          if (c.valid) out = Intersect(out, Widened(c, state.centres[i], lipschitz, margin));
          c = {state.centres[i], out, true};
        }
        intervals[i] = out;
        if (Answers(out, query.clearance)) refined[i] = 1;
      }
      for (int k = 0; k < links; ++k) {
        const Model::LinkSpheresRange& link = model.links[k];
        if (query.per_sphere) {
          for (int i = link.begin; i < link.end; ++i) {
            if (!refined[i]) {
              intervals[i] = ask(i, query.clearance);
              refined[i] = 1;
            }
          }
        }
        // Refine the lowest spheres until the link's interval is tight enough.
        for (;;) {
          ClearanceInterval link_interval{kInf, kInf};
          int lowest = -1;
          for (int i = link.begin; i < link.end; ++i) {
            link_interval.lower = std::min(link_interval.lower, intervals[i].lower);
            link_interval.upper = std::min(link_interval.upper, intervals[i].upper);
            if (!refined[i] && (lowest < 0 || intervals[i].lower < intervals[lowest].lower)) {
              lowest = i;
            }
          }
          if (Answers(link_interval, query.clearance) || lowest < 0) {
            result.link_clearance[static_cast<std::size_t>(s) * links + k] = link_interval;
            break;
          }
          intervals[lowest] = ask(lowest, query.clearance);
          refined[lowest] = 1;
        }
      }
      for (int i = 0; i < spheres && !world; ++i) world = collides(i, intervals[i]);
      if (query.per_sphere) {
        std::copy(intervals.begin(), intervals.end(),
                  result.sphere_clearance.begin() + static_cast<std::ptrdiff_t>(s) * spheres);
      }
    }
    result.world_collision[s] = world;
    if (query.self_collision && (query.intervals || !world)) {
      result.self_collision[s] = self_collides();
    }
    result.collides[s] = world || result.self_collision[s];
  }
  return result;
}

}  // namespace inscribe::robot
