// MoveIt's SRDF (srdfdom's elements): <link_sphere_approximation link="L"> with <sphere
// center="x y z" radius="r"/> children, and <disable_collisions link1 link2 reason/>. Read and
// written with tinyxml2; written into an existing SRDF it replaces only those elements for the
// model's links and pairs.
#include <tinyxml2.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "inscribe/robot/spherized_urdf.h"
#include "robot_spheres_formats.h"

namespace inscribe::robot::internal {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

absl::Status ElementError(const XMLElement& element, const std::string& what) {
  return absl::InvalidArgumentError(
      absl::StrCat("line ", element.GetLineNum(), ": <", element.Name(), "> ", what));
}

absl::StatusOr<std::string> RequiredAttribute(const XMLElement& element, const char* name) {
  const char* value = element.Attribute(name);
  if (value == nullptr || *value == '\0') {
    return ElementError(element, absl::StrCat("has no ", name, " attribute"));
  }
  return std::string(value);
}

absl::StatusOr<Sphere> ReadSphere(const XMLElement& element, const std::string& link) {
  const char* center = element.Attribute("center");
  const char* radius = element.Attribute("radius");
  if (center == nullptr || radius == nullptr) {
    return ElementError(element, absl::StrCat("of link '", link, "' needs center and radius"));
  }
  const std::vector<absl::string_view> tokens =
      absl::StrSplit(center, absl::ByAnyChar(" \t\r\n"), absl::SkipEmpty());
  Sphere sphere;
  bool ok = tokens.size() == 3;
  for (std::size_t k = 0; ok && k < 3; ++k) {
    ok = absl::SimpleAtod(tokens[k], &sphere.center[k]) && std::isfinite(sphere.center[k]);
  }
  if (!ok) {
    return ElementError(element, absl::StrCat("of link '", link, "': center '", center,
                                              "' is not 3 finite numbers"));
  }
  if (!absl::SimpleAtod(radius, &sphere.radius) || !std::isfinite(sphere.radius) ||
      !(sphere.radius > 0.0)) {
    return ElementError(element, absl::StrCat("of link '", link, "': radius '", radius,
                                              "' is not a positive finite number"));
  }
  return sphere;
}

absl::StatusOr<XMLDocument*> ParseDocument(absl::string_view bytes, XMLDocument* document) {
  if (document->Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS ||
      document->RootElement() == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("line ", document->ErrorLineNum(), ": not well-formed XML"));
  }
  if (std::string(document->RootElement()->Name()) != "robot") {
    return absl::InvalidArgumentError(
        absl::StrCat("line ", document->RootElement()->GetLineNum(), ": the root element is <",
                     document->RootElement()->Name(), ">, not <robot>"));
  }
  return document;
}

}  // namespace

absl::StatusOr<RobotSpheres> ParseSrdfRobotSpheres(absl::string_view bytes) {
  XMLDocument document;
  if (absl::StatusOr<XMLDocument*> parsed = ParseDocument(bytes, &document); !parsed.ok()) {
    return parsed.status();
  }
  const XMLElement* root = document.RootElement();
  RobotSpheres model;
  if (const char* name = root->Attribute("name")) model.robot_name = name;
  std::set<std::string> seen;
  for (const XMLElement* element = root->FirstChildElement(); element != nullptr;
       element = element->NextSiblingElement()) {
    const std::string tag = element->Name();
    if (tag == "link_sphere_approximation") {
      absl::StatusOr<std::string> link = RequiredAttribute(*element, "link");
      if (!link.ok()) return link.status();
      if (!seen.insert(*link).second) {
        return ElementError(*element, absl::StrCat("lists link '", *link, "' a second time"));
      }
      LinkSpheres spheres{*link, {}};
      for (const XMLElement* sphere = element->FirstChildElement("sphere"); sphere != nullptr;
           sphere = sphere->NextSiblingElement("sphere")) {
        absl::StatusOr<Sphere> read = ReadSphere(*sphere, *link);
        if (!read.ok()) return read.status();
        spheres.spheres.push_back(*read);
      }
      model.links.push_back(std::move(spheres));
    } else if (tag == "disable_collisions") {
      absl::StatusOr<std::string> a = RequiredAttribute(*element, "link1");
      if (!a.ok()) return a.status();
      absl::StatusOr<std::string> b = RequiredAttribute(*element, "link2");
      if (!b.ok()) return b.status();
      if (*a == *b)
        return ElementError(*element, absl::StrCat("pairs link '", *a, "' with itself"));
      const char* reason = element->Attribute("reason");
      model.self_collision_ignore.emplace(std::minmax(*a, *b), reason == nullptr ? "" : reason);
    }
  }
  return model;
}

absl::StatusOr<std::string> FormatSrdfRobotSpheres(const RobotSpheres& model,
                                                   const RobotSpheresWriteOptions& options) {
  XMLDocument document;
  XMLElement* robot = nullptr;
  std::set<std::string> links;
  for (const LinkSpheres& link : model.links) links.insert(link.link);
  if (options.base.empty()) {
    document.InsertEndChild(document.NewDeclaration());
    if (!options.comment.empty()) {
      document.InsertEndChild(document.NewComment(XmlCommentText(options.comment).c_str()));
    }
    robot = document.NewElement("robot");
    robot->SetAttribute("name", model.robot_name.c_str());
    document.InsertEndChild(robot);
  } else {
    absl::StatusOr<XMLDocument*> parsed = ParseDocument(options.base, &document);
    if (!parsed.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("the SRDF to merge into: ", parsed.status().message()));
    }
    robot = document.RootElement();
    if (const XMLElement* link = robot->FirstChildElement("link"); link != nullptr) {
      return absl::InvalidArgumentError(absl::StrCat("the SRDF to merge into has a <link> (line ",
                                                     link->GetLineNum(),
                                                     "): it is a URDF, not an SRDF"));
    }
    if (robot->Attribute("name") == nullptr) robot->SetAttribute("name", model.robot_name.c_str());
    // Ours replace the elements about the same links and pairs; the rest stays as it was.
    std::vector<XMLElement*> replaced;
    for (XMLElement* element = robot->FirstChildElement(); element != nullptr;
         element = element->NextSiblingElement()) {
      const std::string tag = element->Name();
      const char* link = element->Attribute("link");
      const char* a = element->Attribute("link1");
      const char* b = element->Attribute("link2");
      if (tag == "link_sphere_approximation" && link != nullptr && links.count(link) != 0) {
        replaced.push_back(element);
      } else if (tag == "disable_collisions" && a != nullptr && b != nullptr &&
                 model.self_collision_ignore.count(std::minmax(std::string(a), std::string(b))) !=
                     0) {
        replaced.push_back(element);
      }
    }
    for (XMLElement* element : replaced) robot->DeleteChild(element);
    if (!options.comment.empty()) {
      robot->InsertEndChild(document.NewComment(XmlCommentText(options.comment).c_str()));
    }
  }
  for (const LinkSpheres& link : model.links) {
    XMLElement* approximation = robot->InsertNewChildElement("link_sphere_approximation");
    approximation->SetAttribute("link", link.link.c_str());
    for (const Sphere& s : link.spheres) {
      XMLElement* sphere = approximation->InsertNewChildElement("sphere");
      const std::string center =
          absl::StrCat(ShortestDecimal(s.center.x()), " ", ShortestDecimal(s.center.y()), " ",
                       ShortestDecimal(s.center.z()));
      sphere->SetAttribute("center", center.c_str());
      sphere->SetAttribute("radius", ShortestDecimal(s.radius).c_str());
    }
  }
  for (const auto& [pair, reason] : model.self_collision_ignore) {
    XMLElement* element = robot->InsertNewChildElement("disable_collisions");
    element->SetAttribute("link1", pair.first.c_str());
    element->SetAttribute("link2", pair.second.c_str());
    if (!reason.empty()) element->SetAttribute("reason", reason.c_str());
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return std::string(printer.CStr(), static_cast<std::size_t>(printer.CStrSize() - 1));
}

}  // namespace inscribe::robot::internal
