// Private: the robot model behind RobotStateChecker (robot_states.h), shared by its state
// and segment checks.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/robot/robot_states.h"

namespace inscribe::robot {

struct RobotStateChecker::Model {
  Kinematics kinematics;
  struct LinkSpheresRange {
    int link = -1;                               // Kinematics index
    int begin = 0, end = 0;                      // its spheres in `local`
    Vector3 bound_centre = Vector3::Zero();      // link frame
    double bound_world = 0.0, bound_self = 0.0;  // radii holding its padded spheres
  };
  std::vector<LinkSpheresRange> links;  // the checked links, in the model's order
  std::vector<std::string> link_names;
  std::vector<Vector3> local;        // per sphere, its centre in its link's frame
  std::vector<double> world_radius;  // radius + collision_buffer
  std::vector<double> self_radius;   // radius + self_collision_buffer
  std::vector<int> sphere_link;      // per sphere, index into `links`
  std::vector<std::pair<int, int>> self_pairs;
  // Per Kinematics link, its joint's motion for the travel bounds (the root's unused).
  struct JointBound {
    UrdfJointType type = UrdfJointType::kFixed;
    int variable = -1;
    double multiplier = 1.0, offset = 0.0;
    double origin = 0.0;  // |origin translation|
    double anchor = 0.0;  // |anchor|
  };
  std::vector<JointBound> joints;
  double scale = 0.0;  // largest |local centre| + radius, plus the robot's reach

  explicit Model(Kinematics k) : kinematics(std::move(k)) {}
};

// The posed state every check starts from: link poses, then the spheres' centres, link by
// link when first needed (yes/no checks pose only the links their bounding balls do not clear).
struct PosedState {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<Sphere> world;  // world-padded spheres
  std::vector<Vector3> centres;
  std::vector<std::uint8_t> link_posed;  // per checked link
  std::vector<Vector3> bound_centres;    // per checked link, its bounding balls' centre
};

// The link poses at `q` into *state, no sphere posed yet. Errors: Kinematics::LinkPoses'.
absl::Status PoseLinks(const RobotStateChecker::Model& model, absl::Span<const double> q,
                       PosedState* state);
// Poses checked link k's spheres, once per PoseLinks.
void PoseLinkSpheres(const RobotStateChecker::Model& model, int k, PosedState* state);
// PoseLinks, then every link's spheres.
absl::Status PoseState(const RobotStateChecker::Model& model, absl::Span<const double> q,
                       PosedState* state);

// Whether links a and b (indices into model.links) overlap at the posed state, and, when
// `distance` is given, the smallest |c_a - c_b| - r_a - r_b over their sphere pairs (self
// radii), computed in full (no early exit). Poses the two links' spheres when needed.
bool LinksCollide(const RobotStateChecker::Model& model, PosedState* state, int a, int b,
                  double* distance);

// The rounding margin of distances between posed spheres of the robot.
double RobotMargin(const RobotStateChecker::Model& model);

}  // namespace inscribe::robot
