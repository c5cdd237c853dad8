// The self-collision matrix as MoveIt's SRDF: the disabled pairs as the setup assistant writes
// them.
#pragma once

#include <string>

#include "inscribe/robot/self_collision.h"

namespace inscribe::robot {

// An SRDF document: <robot name="robot_name"> holding, for every pair the matrix disables
// (every class but Sometimes), <disable_collisions link1="A" link2="B" reason="R"/> with A < B
// (byte order) and R one of Adjacent, Default, Always, Never; sorted by (A, B), as MoveIt's
// setup assistant orders its pairs. A leading comment states the samples, seed and whether the
// bounds are certified. Names are escaped by tinyxml2's printer. O(#pairs log #pairs).
// Written through FormatRobotSpheres (kSrdf), the one SRDF writer.
std::string SelfCollisionSrdf(const SelfCollisionMatrix& matrix, const std::string& robot_name);

// "inscribe: self-collision matrix over N random configurations (seed S), ...": the comment the
// SRDF and the other sphere files made with a matrix start with.
std::string SelfCollisionComment(const SelfCollisionMatrix& matrix);

}  // namespace inscribe::robot
