#include "inscribe/robot/self_collision_srdf.h"

#include <cassert>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/robot_spheres.h"

namespace inscribe::robot {

std::string SelfCollisionSrdf(const SelfCollisionMatrix& matrix, const std::string& robot_name) {
  RobotSpheres model;
  model.robot_name = robot_name;
  for (const LinkPairCollision& pair : matrix.pairs) {
    if (!CollisionDisabled(pair.type)) continue;
    model.self_collision_ignore[std::minmax(matrix.links[pair.link_a], matrix.links[pair.link_b])] =
        CollisionPairClassName(pair.type);
  }
  RobotSpheresWriteOptions options;
  options.comment = SelfCollisionComment(matrix);
  absl::StatusOr<std::string> srdf = FormatRobotSpheres(model, RobotSpheresFormat::kSrdf, options);
  assert(srdf.ok());  // the matrix's pairs are distinct, named links, ordered
  return *std::move(srdf);
}

std::string SelfCollisionComment(const SelfCollisionMatrix& matrix) {
  return absl::StrCat(
      "inscribe: self-collision matrix over ", matrix.samples, " random configurations (seed ",
      matrix.seed, "), always at ", matrix.always_fraction, "; bounds ",
      matrix.certified ? "certified for the links' solids" : "for the spheres only");
}

}  // namespace inscribe::robot
