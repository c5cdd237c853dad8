#include "inscribe/robot/kinematics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace inscribe::robot {

// Links are visited parents first (`order`); a link's pose is its parent's pose times `origin`
// times the motion of its joint, whose value is multiplier * q[variable] + offset (variable
// -1: no motion).
struct Kinematics::Tree {
  std::vector<std::string> link_names;
  int root = 0;
  std::vector<int> parent;        // per link, -1 for the root
  std::vector<int> parent_joint;  // per link, -1 for the root
  std::vector<int> order;         // links, every parent before its children
  std::vector<JointVariable> variables;
  std::map<std::string, int> variable_index;
  struct Motion {
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
    UrdfJointType type = UrdfJointType::kFixed;
    Vector3 axis = Vector3::UnitX();
    Vector3 anchor = Vector3::Zero();  // UrdfJoint::anchor
    int variable = -1;
    double multiplier = 1.0;
    double offset = 0.0;
  };
  std::vector<Motion> motion;  // per link, the root's unused
};

namespace {

bool HasVariable(UrdfJointType type) {
  return type == UrdfJointType::kRevolute || type == UrdfJointType::kContinuous ||
         type == UrdfJointType::kPrismatic;
}

absl::Status JointError(const UrdfJoint& joint, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat("joint '", joint.name, "' (URDF line ", joint.line, "): ", what));
}

// Where each joint's value comes from: its own variable or, through a chain of mimics, the
// variable at the chain's end, as value = multiplier * q[variable] + offset.
struct Source {
  int variable = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};

absl::StatusOr<std::vector<Source>> ResolveMimics(const UrdfRobot& robot,
                                                  const std::map<std::string, int>& joint_index,
                                                  const std::vector<int>& own_variable) {
  const int n = static_cast<int>(robot.joints.size());
  std::vector<Source> source(n);
  for (int j = 0; j < n; ++j) {
    const UrdfJoint& joint = robot.joints[j];
    if (!HasVariable(joint.type)) continue;
    Source s;
    int at = j;
    std::vector<bool> seen(n, false);
    while (robot.joints[at].mimic) {
      seen[at] = true;
      const UrdfMimic& mimic = *robot.joints[at].mimic;
      const auto target = joint_index.find(mimic.joint);
      if (target == joint_index.end()) {
        return JointError(robot.joints[at],
                          absl::StrCat("mimics joint '", mimic.joint, "', which does not exist"));
      }
      if (target->second == at) return JointError(robot.joints[at], "mimics itself");
      const UrdfJoint& of = robot.joints[target->second];
      if (!HasVariable(of.type)) {
        return JointError(robot.joints[at],
                          absl::StrCat("mimics joint '", of.name, "', a ",
                                       UrdfJointTypeName(of.type), " joint without a value"));
      }
      if (seen[target->second]) {
        return JointError(joint,
                          absl::StrCat("its chain of mimics loops at joint '", of.name, "'"));
      }
      // value(at) = m * value(target) + o, and value(j) = s.multiplier * value(at) + s.offset.
      s.offset += s.multiplier * mimic.offset;
      s.multiplier *= mimic.multiplier;
      at = target->second;
    }
    if (!std::isfinite(s.multiplier) || !std::isfinite(s.offset)) {
      return JointError(joint, "its chain of mimics overflows (multiplier or offset not finite)");
    }
    s.variable = own_variable[at];
    source[j] = s;
  }
  return source;
}

// The top 53 bits as a multiple of 2^-53: exact, in [0, 1), the same on every machine.
double UnitInterval(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

constexpr double kPi = 3.14159265358979323846;

}  // namespace

Kinematics::Kinematics(std::shared_ptr<const Tree> tree) : tree_(std::move(tree)) {}

absl::StatusOr<Kinematics> Kinematics::Create(const UrdfRobot& robot) {
  auto tree = std::make_shared<Tree>();
  const int links = static_cast<int>(robot.links.size());
  if (links == 0) return absl::InvalidArgumentError("the robot has no links");
  std::map<std::string, int> link_index;
  for (int i = 0; i < links; ++i) {
    if (robot.links[i].name.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("link ", i, " (URDF line ", robot.links[i].line, ") has no name"));
    }
    if (!link_index.emplace(robot.links[i].name, i).second) {
      return absl::InvalidArgumentError(absl::StrCat("link name '", robot.links[i].name,
                                                     "' is used twice (URDF line ",
                                                     robot.links[i].line, ")"));
    }
    tree->link_names.push_back(robot.links[i].name);
  }
  tree->parent.assign(links, -1);
  tree->parent_joint.assign(links, -1);
  tree->motion.resize(links);

  // Joints one by one: names, links, axis, limits; variables in joint order.
  std::map<std::string, int> joint_index;
  std::vector<int> own_variable(robot.joints.size(), -1);
  for (int j = 0; j < static_cast<int>(robot.joints.size()); ++j) {
    const UrdfJoint& joint = robot.joints[j];
    if (joint.name.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint ", j, " (URDF line ", joint.line, ") has no name"));
    }
    if (!joint_index.emplace(joint.name, j).second) {
      return JointError(joint, "its name is used by an earlier joint");
    }
    const auto parent = link_index.find(joint.parent);
    if (parent == link_index.end()) {
      return JointError(joint, absl::StrCat("parent link '", joint.parent, "' does not exist"));
    }
    const auto child = link_index.find(joint.child);
    if (child == link_index.end()) {
      return JointError(joint, absl::StrCat("child link '", joint.child, "' does not exist"));
    }
    if (tree->parent_joint[child->second] >= 0) {
      return JointError(joint,
                        absl::StrCat("link '", joint.child, "' is already the child of joint '",
                                     robot.joints[tree->parent_joint[child->second]].name, "'"));
    }
    const bool has_axis =
        joint.type != UrdfJointType::kFixed && joint.type != UrdfJointType::kFloating;
    if (has_axis && !(joint.axis.allFinite() && joint.axis.norm() > 0.0)) {
      return JointError(joint, "its axis is zero or not finite");
    }
    if (!joint.origin.xyz.allFinite() || !joint.origin.rpy.allFinite() ||
        (joint.origin.rotation && !joint.origin.rotation->allFinite()) ||
        !joint.anchor.allFinite()) {
      return JointError(joint, "its origin is not finite");
    }
    const bool limited =
        joint.type == UrdfJointType::kRevolute || joint.type == UrdfJointType::kPrismatic;
    if (limited && !(std::isfinite(joint.lower) && std::isfinite(joint.upper))) {
      return JointError(joint, "its limits are not finite");
    }
    if (limited && joint.lower > joint.upper) {
      return JointError(joint,
                        absl::StrCat("lower limit ", joint.lower, " > upper limit ", joint.upper));
    }
    if (joint.mimic &&
        !(std::isfinite(joint.mimic->multiplier) && std::isfinite(joint.mimic->offset))) {
      return JointError(joint, "its mimic multiplier or offset is not finite");
    }
    tree->parent[child->second] = parent->second;
    tree->parent_joint[child->second] = j;
    if (HasVariable(joint.type) && !joint.mimic) {
      JointVariable variable;
      variable.joint = joint.name;
      variable.type = joint.type;
      const bool continuous = joint.type == UrdfJointType::kContinuous;
      variable.lower = continuous ? -kPi : joint.lower;
      variable.upper = continuous ? kPi : joint.upper;
      own_variable[j] = static_cast<int>(tree->variables.size());
      tree->variable_index.emplace(joint.name, own_variable[j]);
      tree->variables.push_back(std::move(variable));
    }
  }

  absl::StatusOr<std::vector<Source>> sources = ResolveMimics(robot, joint_index, own_variable);
  if (!sources.ok()) return sources.status();

  // The root, then every link reachable from it, parents first. With one parent per link, a
  // link not reached lies on a cycle or below one.
  std::vector<int> roots;
  for (int i = 0; i < links; ++i) {
    if (tree->parent[i] < 0) roots.push_back(i);
  }
  if (roots.size() > 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the robot has ", roots.size(), " root links (links no joint has as child), e.g. '",
        tree->link_names[roots[0]], "' and '", tree->link_names[roots[1]],
        "'; a URDF is one tree"));
  }
  std::vector<std::vector<int>> children(links);
  for (int i = 0; i < links; ++i) {
    if (tree->parent[i] >= 0) children[tree->parent[i]].push_back(i);
  }
  if (!roots.empty()) {
    tree->root = roots[0];
    tree->order.push_back(roots[0]);
    for (std::size_t at = 0; at < tree->order.size(); ++at) {
      for (int child : children[tree->order[at]]) tree->order.push_back(child);
    }
  }
  if (static_cast<int>(tree->order.size()) != links) {
    std::vector<bool> reached(links, false);
    for (int link : tree->order) reached[link] = true;
    // Walk up from an unreached link until a link repeats: that link is on the cycle.
    int at = 0;
    while (reached[at]) ++at;
    std::vector<bool> seen(links, false);
    while (!seen[at]) {
      seen[at] = true;
      at = tree->parent[at];
    }
    return JointError(robot.joints[tree->parent_joint[at]],
                      absl::StrCat("it closes a cycle through link '", tree->link_names[at],
                                   "'; a URDF is a tree"));
  }

  for (int link = 0; link < links; ++link) {
    const int j = tree->parent_joint[link];
    if (j < 0) continue;
    const UrdfJoint& joint = robot.joints[j];
    Tree::Motion& m = tree->motion[link];
    m.origin = Eigen::Isometry3d::Identity();
    m.origin.linear() = OriginRotation(joint.origin);
    m.origin.translation() = joint.origin.xyz;
    m.type = joint.type;
    m.axis = joint.axis.normalized();
    m.anchor = joint.anchor;
    m.variable = (*sources)[j].variable;
    m.multiplier = (*sources)[j].multiplier;
    m.offset = (*sources)[j].offset;
  }
  return Kinematics(std::move(tree));
}

int Kinematics::links() const { return static_cast<int>(tree_->link_names.size()); }
const std::string& Kinematics::link_name(int link) const { return tree_->link_names[link]; }
int Kinematics::root() const { return tree_->root; }
int Kinematics::parent(int link) const { return tree_->parent[link]; }
int Kinematics::parent_joint(int link) const { return tree_->parent_joint[link]; }
const std::vector<JointVariable>& Kinematics::variables() const { return tree_->variables; }

Kinematics::JointDrive Kinematics::drive(int link) const {
  const Tree::Motion& m = tree_->motion[link];
  if (tree_->parent_joint[link] < 0 || m.variable < 0) return {};
  return {m.variable, m.multiplier, m.offset};
}

int Kinematics::variable(const std::string& joint) const {
  const auto found = tree_->variable_index.find(joint);
  return found == tree_->variable_index.end() ? -1 : found->second;
}

absl::Status Kinematics::LinkPoses(absl::Span<const double> q,
                                   std::vector<Eigen::Isometry3d>* poses) const {
  const Tree& tree = *tree_;
  if (q.size() != tree.variables.size()) {
    return absl::InvalidArgumentError(absl::StrCat("configuration has ", q.size(),
                                                   " values; the robot has ", tree.variables.size(),
                                                   " variables"));
  }
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (!std::isfinite(q[i])) {
      return absl::InvalidArgumentError(absl::StrCat("configuration value ", i, " (joint '",
                                                     tree.variables[i].joint, "') is not finite"));
    }
  }
  poses->resize(tree.link_names.size());
  for (int link : tree.order) {
    const int parent = tree.parent[link];
    if (parent < 0) {
      (*poses)[link] = Eigen::Isometry3d::Identity();
      continue;
    }
    const Tree::Motion& m = tree.motion[link];
    Eigen::Isometry3d pose = (*poses)[parent] * m.origin;
    if (m.variable >= 0) {
      const double value = m.multiplier * q[m.variable] + m.offset;
      if (!std::isfinite(value)) {
        return absl::InvalidArgumentError(
            absl::StrCat("the value of the joint of link '", tree.link_names[link], "' (",
                         m.multiplier, " * ", q[m.variable], " + ", m.offset, ") is not finite"));
      }
      if (m.type == UrdfJointType::kPrismatic) {
        pose.translate(value * m.axis);
      } else if (m.anchor.isZero()) {
        pose.rotate(Eigen::AngleAxisd(value, m.axis));
      } else {
        pose.translate(m.anchor);
        pose.rotate(Eigen::AngleAxisd(value, m.axis));
        pose.translate(-m.anchor);
      }
    }
    (*poses)[link] = pose;
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<Eigen::Isometry3d>> Kinematics::LinkPoses(
    const std::vector<double>& q) const {
  std::vector<Eigen::Isometry3d> poses;
  if (absl::Status status = LinkPoses(absl::MakeConstSpan(q), &poses); !status.ok()) {
    return status;
  }
  return poses;
}

ConfigurationSampler::ConfigurationSampler(const Kinematics& kinematics, std::uint64_t seed)
    : generator_(seed) {
  for (const JointVariable& variable : kinematics.variables()) {
    lower_.push_back(variable.lower);
    width_.push_back(variable.upper - variable.lower);
  }
}

void ConfigurationSampler::Next(absl::Span<double> q) {
  assert(q.size() == lower_.size());
  for (std::size_t i = 0; i < lower_.size(); ++i) {
    q[i] = lower_[i] + UnitInterval(generator_()) * width_[i];
  }
}

std::vector<std::vector<double>> SampleConfigurations(const Kinematics& kinematics,
                                                      std::int64_t count, std::uint64_t seed) {
  ConfigurationSampler sampler(kinematics, seed);
  std::vector<std::vector<double>> samples(
      static_cast<std::size_t>(std::max<std::int64_t>(0, count)),
      std::vector<double>(kinematics.variables().size()));
  for (std::vector<double>& q : samples) sampler.Next(absl::MakeSpan(q));
  return samples;
}

std::vector<double> DefaultConfiguration(const Kinematics& kinematics) {
  std::vector<double> q;
  for (const JointVariable& variable : kinematics.variables()) {
    const bool zero_inside = variable.lower <= 0.0 && 0.0 <= variable.upper;
    q.push_back(zero_inside ? 0.0 : 0.5 * (variable.lower + variable.upper));
  }
  return q;
}

}  // namespace inscribe::robot
