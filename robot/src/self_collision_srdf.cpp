#include "inscribe/robot/self_collision_srdf.h"

#include <tinyxml2.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"

namespace inscribe::robot {

std::string SelfCollisionSrdf(const SelfCollisionMatrix& matrix, const std::string& robot_name) {
  std::vector<std::tuple<std::string, std::string, const char*>> disabled;
  for (const LinkPairCollision& pair : matrix.pairs) {
    if (!CollisionDisabled(pair.type)) continue;
    std::string a = matrix.links[pair.link_a], b = matrix.links[pair.link_b];
    if (b < a) std::swap(a, b);
    disabled.emplace_back(std::move(a), std::move(b), CollisionPairClassName(pair.type));
  }
  std::sort(disabled.begin(), disabled.end());

  tinyxml2::XMLDocument document;
  document.InsertEndChild(document.NewDeclaration());
  std::string comment = absl::StrCat(
      " inscribe: self-collision matrix over ", matrix.samples, " random configurations (seed ",
      matrix.seed, "), always at ", matrix.always_fraction, "; bounds ",
      matrix.certified ? "certified for the links' solids" : "for the spheres only", " ");
  document.InsertEndChild(document.NewComment(comment.c_str()));
  tinyxml2::XMLElement* robot = document.NewElement("robot");
  robot->SetAttribute("name", robot_name.c_str());
  document.InsertEndChild(robot);
  for (const auto& [a, b, reason] : disabled) {
    tinyxml2::XMLElement* element = robot->InsertNewChildElement("disable_collisions");
    element->SetAttribute("link1", a.c_str());
    element->SetAttribute("link2", b.c_str());
    element->SetAttribute("reason", reason);
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return std::string(printer.CStr(), static_cast<std::size_t>(printer.CStrSize() - 1));
}

}  // namespace inscribe::robot
