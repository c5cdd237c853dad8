// Spheres in URDF: VAMP's and cricket's layout (one sphere <collision> per sphere in the link)
// and MorphIt's (one child link per sphere on a fixed joint). Read through ParseUrdf (its
// numbers, lines and origins); written by editing the base URDF with tinyxml2.
#include <tinyxml2.h>

#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"
#include "robot_spheres_formats.h"

namespace inscribe::robot::internal {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;
using tinyxml2::XMLNode;

std::string Xyz(const Vector3& p) {
  return absl::StrCat(ShortestDecimal(p.x()), " ", ShortestDecimal(p.y()), " ",
                      ShortestDecimal(p.z()));
}

// <tag><origin xyz rpy="0 0 0"/><geometry><sphere radius/></geometry></tag>
XMLElement* SphereElement(XMLDocument& document, const char* tag, const Vector3& center,
                          double radius) {
  XMLElement* element = document.NewElement(tag);
  XMLElement* origin = element->InsertNewChildElement("origin");
  origin->SetAttribute("xyz", Xyz(center).c_str());
  origin->SetAttribute("rpy", "0 0 0");
  element->InsertNewChildElement("geometry")
      ->InsertNewChildElement("sphere")
      ->SetAttribute("radius", ShortestDecimal(radius).c_str());
  return element;
}

std::string AttributeOf(const XMLElement* element, const char* name) {
  const char* value = element == nullptr ? nullptr : element->Attribute(name);
  return value == nullptr ? std::string() : std::string(value);
}

// MorphIt's sphere links of the base: child name -> (parent name, joint element), for every
// fixed joint whose child is named "<parent>_sphere<k>".
std::map<std::string, std::pair<std::string, XMLElement*>> MorphitChildren(XMLElement& robot) {
  std::map<std::string, std::pair<std::string, XMLElement*>> children;
  for (XMLElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    if (AttributeOf(joint, "type") != "fixed") continue;
    const std::string parent = AttributeOf(joint->FirstChildElement("parent"), "link");
    const std::string child = AttributeOf(joint->FirstChildElement("child"), "link");
    if (!parent.empty() && MorphitParentName(child) == parent) {
      children[child] = {parent, joint};
    }
  }
  return children;
}

absl::StatusOr<XMLDocument*> ParseBase(absl::string_view base, XMLDocument* document) {
  if (base.empty()) {
    return absl::InvalidArgumentError(
        "writing spheres into a URDF needs the robot's URDF to write them into");
  }
  if (document->Parse(base.data(), base.size()) != tinyxml2::XML_SUCCESS ||
      document->RootElement() == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("the base URDF, line ", document->ErrorLineNum(), ": not well-formed XML"));
  }
  if (std::string(document->RootElement()->Name()) != "robot") {
    return absl::InvalidArgumentError(absl::StrCat(
        "the base URDF's root element is <", document->RootElement()->Name(), ">, not <robot>"));
  }
  return document;
}

}  // namespace

std::string XmlCommentText(const std::string& text) {
  std::string safe = text;
  while (safe.find("--") != std::string::npos) safe = absl::StrReplaceAll(safe, {{"--", "- -"}});
  return " " + safe + " ";
}

std::string MorphitParentName(const std::string& link) {
  constexpr char kMarker[] = "_sphere";
  const std::size_t at = link.rfind(kMarker);
  if (at == std::string::npos || at == 0) return "";
  const absl::string_view digits = absl::string_view(link).substr(at + sizeof kMarker - 1);
  if (digits.empty()) return "";
  for (char c : digits) {
    if (!absl::ascii_isdigit(static_cast<unsigned char>(c))) return "";
  }
  return link.substr(0, at);
}

bool HasMorphitSphereLinks(absl::string_view bytes) {
  XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS ||
      document.RootElement() == nullptr) {
    return false;
  }
  return !MorphitChildren(*document.RootElement()).empty();
}

void RemoveSphereComments(XMLElement& link) {
  std::vector<XMLNode*> ours;
  for (XMLNode* node = link.FirstChild(); node != nullptr; node = node->NextSibling()) {
    if (node->ToComment() == nullptr) continue;
    const std::string text = node->Value();
    if (text.find(kSphereCommentMark) != std::string::npos) ours.push_back(node);
  }
  for (XMLNode* node : ours) link.DeleteChild(node);
}

void ReplaceLinkCollisions(XMLDocument& document, XMLElement& link,
                           const std::vector<Sphere>& spheres, const std::string& comment) {
  RemoveSphereComments(link);
  // Where the new elements go: where the first <collision> was, else after the last <visual>,
  // else last.
  XMLNode* anchor = nullptr;
  if (XMLElement* first = link.FirstChildElement("collision"); first != nullptr) {
    anchor = first->PreviousSibling();
  } else {
    for (XMLElement* visual = link.FirstChildElement("visual"); visual != nullptr;
         visual = visual->NextSiblingElement("visual")) {
      anchor = visual;
    }
    if (anchor == nullptr) anchor = link.LastChild();
  }
  while (XMLElement* collision = link.FirstChildElement("collision")) link.DeleteChild(collision);
  XMLNode* last = document.NewComment(XmlCommentText(comment).c_str());
  if (anchor == nullptr) {
    link.InsertFirstChild(last);
  } else {
    link.InsertAfterChild(anchor, last);
  }
  for (const Sphere& sphere : spheres) {
    last = link.InsertAfterChild(
        last, SphereElement(document, "collision", sphere.center, sphere.radius));
  }
}

absl::StatusOr<RobotSpheres> ParseUrdfRobotSpheres(absl::string_view bytes) {
  absl::StatusOr<UrdfRobot> robot = ParseUrdf(bytes);
  if (!robot.ok()) return robot.status();
  std::map<std::string, const UrdfJoint*> fixed_by_child, by_child;
  for (const UrdfJoint& joint : robot->joints) {
    // Which joint places a sphere link must be clear: a link has one parent joint.
    if (const auto [seen, first] = by_child.emplace(joint.child, &joint); !first) {
      return absl::InvalidArgumentError(absl::StrCat(
          "line ", joint.line, ": joint '", joint.name, "' has child link '", joint.child,
          "', the child of joint '", seen->second->name, "' (line ", seen->second->line, ") too"));
    }
    if (joint.type == UrdfJointType::kFixed) fixed_by_child[joint.child] = &joint;
  }
  // Per link, its own sphere collisions in the link frame; false when it has none.
  std::map<std::string, std::vector<Sphere>> own;
  auto read_link = [&](const UrdfLink& link) -> absl::StatusOr<bool> {
    if (link.from_visual) return false;
    std::vector<Sphere> spheres;
    const UrdfElement* other = nullptr;
    for (const UrdfElement& element : link.elements) {
      if (element.geometry.shape == UrdfShape::kSphere) {
        spheres.push_back(Sphere{element.origin.xyz, element.geometry.radius});
      } else if (other == nullptr) {
        other = &element;
      }
    }
    if (spheres.empty()) return false;  // other geometry only: not spherized, not in the model
    if (other != nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(
          DescribeUrdfElement(*other, false), " of link '", link.name,
          "' is not a sphere, but the link has sphere collisions: a spherized link holds only "
          "spheres"));
    }
    own[link.name] = std::move(spheres);
    return true;
  };

  RobotSpheres model;
  model.robot_name = robot->name;
  std::map<std::string, std::vector<Sphere>> from_children;
  std::set<std::string> sphere_links;
  for (const UrdfLink& link : robot->links) {
    const std::string parent = MorphitParentName(link.name);
    const auto joint = fixed_by_child.find(link.name);
    if (parent.empty() || joint == fixed_by_child.end() || joint->second->parent != parent) {
      continue;
    }
    absl::StatusOr<bool> has = read_link(link);
    if (!has.ok()) return has.status();
    if (!*has) {
      return absl::InvalidArgumentError(absl::StrCat("line ", link.line, ": MorphIt sphere link '",
                                                     link.name, "' has no sphere <collision>"));
    }
    sphere_links.insert(link.name);
    // The child's frame in the parent's: p -> R p + t of the fixed joint's origin.
    const Eigen::Matrix3d rotation = OriginRotation(joint->second->origin);
    for (const Sphere& s : own[link.name]) {
      from_children[parent].push_back(
          Sphere{rotation * s.center + joint->second->origin.xyz, s.radius});
    }
  }
  for (const UrdfLink& link : robot->links) {
    if (sphere_links.count(link.name) != 0) continue;
    absl::StatusOr<bool> has = read_link(link);
    if (!has.ok()) return has.status();
    std::vector<Sphere> spheres = *has ? own[link.name] : std::vector<Sphere>();
    const auto children = from_children.find(link.name);
    if (children != from_children.end()) {
      spheres.insert(spheres.end(), children->second.begin(), children->second.end());
    }
    if (!spheres.empty()) model.links.push_back(LinkSpheres{link.name, std::move(spheres)});
  }
  return model;
}

absl::StatusOr<std::string> FormatUrdfRobotSpheres(const RobotSpheres& model, bool morphit,
                                                   const RobotSpheresWriteOptions& options) {
  XMLDocument document;
  if (absl::StatusOr<XMLDocument*> parsed = ParseBase(options.base, &document); !parsed.ok()) {
    return parsed.status();
  }
  XMLElement& robot = *document.RootElement();
  std::map<std::string, XMLElement*> links;
  for (XMLElement* link = robot.FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    links.emplace(AttributeOf(link, "name"), link);
  }
  std::set<std::string> joints;
  std::multiset<std::string> joint_children;
  for (XMLElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    joints.insert(AttributeOf(joint, "name"));
    joint_children.insert(AttributeOf(joint->FirstChildElement("child"), "link"));
  }
  for (const LinkSpheres& link : model.links) {
    if (!link.spheres.empty() && links.count(link.link) == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("link '", link.link, "' is not in the base URDF"));
    }
  }
  // The base's own MorphIt sphere links of the model's links go: the model replaces them.
  std::set<std::string> written;
  for (const LinkSpheres& link : model.links) {
    if (!link.spheres.empty()) written.insert(link.link);
  }
  for (const auto& [child, parent_joint] : MorphitChildren(robot)) {
    if (written.count(parent_joint.first) == 0) continue;
    joints.erase(AttributeOf(parent_joint.second, "name"));
    joint_children.erase(joint_children.find(child));
    robot.DeleteChild(parent_joint.second);
    // The joint may name a link the document lacks (the tree is Kinematics' to check).
    if (const auto link = links.find(child); link != links.end()) {
      robot.DeleteChild(link->second);
      links.erase(link);
    }
  }
  const std::string comment_start = options.comment.empty() ? "inscribe" : options.comment;
  for (const LinkSpheres& link : model.links) {
    if (link.spheres.empty()) continue;
    XMLElement& element = *links.at(link.link);
    const std::string comment =
        absl::StrCat(comment_start, ": ", link.spheres.size(), " ", kSphereCommentMark,
                     morphit ? " (MorphIt: one child link per sphere)" : "");
    if (!morphit) {
      ReplaceLinkCollisions(document, element, link.spheres, comment);
      continue;
    }
    while (XMLElement* collision = element.FirstChildElement("collision")) {
      element.DeleteChild(collision);
    }
    RemoveSphereComments(element);
    element.InsertEndChild(document.NewComment(XmlCommentText(comment).c_str()));
    XMLNode* last = &element;
    for (std::size_t k = 0; k < link.spheres.size(); ++k) {
      const Sphere& s = link.spheres[k];
      const std::string child = absl::StrCat(link.link, "_sphere", k);
      const std::string joint_name = absl::StrCat(link.link, "_to_", child);
      if (joint_children.count(child) != 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("the base URDF has a joint to a link named '", child,
                         "', the name of a MorphIt sphere of link '", link.link, "'"));
      }
      if (links.count(child) != 0 || joints.count(joint_name) != 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("the base URDF already has a ", links.count(child) != 0 ? "link" : "joint",
                         " named '", links.count(child) != 0 ? child : joint_name,
                         "', the name of a MorphIt sphere of link '", link.link, "'"));
      }
      XMLElement* sphere_link = document.NewElement("link");
      sphere_link->SetAttribute("name", child.c_str());
      sphere_link->InsertEndChild(SphereElement(document, "visual", Vector3::Zero(), s.radius));
      sphere_link->InsertEndChild(SphereElement(document, "collision", Vector3::Zero(), s.radius));
      last = robot.InsertAfterChild(last, sphere_link);
      XMLElement* joint = document.NewElement("joint");
      joint->SetAttribute("name", joint_name.c_str());
      joint->SetAttribute("type", "fixed");
      joint->InsertNewChildElement("parent")->SetAttribute("link", link.link.c_str());
      joint->InsertNewChildElement("child")->SetAttribute("link", child.c_str());
      XMLElement* origin = joint->InsertNewChildElement("origin");
      origin->SetAttribute("xyz", Xyz(s.center).c_str());
      origin->SetAttribute("rpy", "0 0 0");
      last = robot.InsertAfterChild(last, joint);
    }
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return std::string(printer.CStr(), static_cast<std::size_t>(printer.CStrSize() - 1));
}

}  // namespace inscribe::robot::internal
