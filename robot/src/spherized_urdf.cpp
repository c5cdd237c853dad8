#include "inscribe/robot/spherized_urdf.h"

#include <tinyxml2.h>

#include <cassert>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/match.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "inscribe/balls/sphere_io.h"

namespace inscribe::robot {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;
using tinyxml2::XMLNode;

// Text that is safe inside <!-- -->: no "--", and no '-' just before the closing "-->".
std::string CommentText(const std::string& text) {
  std::string safe = text;
  while (safe.find("--") != std::string::npos) safe = absl::StrReplaceAll(safe, {{"--", "- -"}});
  return " " + safe + " ";
}

XMLElement* SphereCollision(XMLDocument& document, const Sphere& sphere) {
  XMLElement* collision = document.NewElement("collision");
  XMLElement* origin = collision->InsertNewChildElement("origin");
  const std::string xyz =
      absl::StrCat(ShortestDecimal(sphere.center.x()), " ", ShortestDecimal(sphere.center.y()), " ",
                   ShortestDecimal(sphere.center.z()));
  origin->SetAttribute("xyz", xyz.c_str());
  origin->SetAttribute("rpy", "0 0 0");
  XMLElement* geometry = collision->InsertNewChildElement("geometry");
  geometry->InsertNewChildElement("sphere")->SetAttribute("radius",
                                                          ShortestDecimal(sphere.radius).c_str());
  return collision;
}

// Replaces the link's <collision> children by the comment and one <collision> per sphere.
void ReplaceCollisions(XMLDocument& document, XMLElement& link, const LinkSpherizeResult& result) {
  // Where the new elements go: after `anchor`, or first when it is null.
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

  XMLNode* last = document.NewComment(
      CommentText(absl::StrCat("inscribe urdf: ", result.spheres.size(),
                               " spheres in place of the link's ",
                               result.from_visual ? "visual" : "collision", " geometry"))
          .c_str());
  if (anchor == nullptr) {
    link.InsertFirstChild(last);
  } else {
    link.InsertAfterChild(anchor, last);
  }
  for (const Sphere& sphere : result.spheres) {
    last = link.InsertAfterChild(last, SphereCollision(document, sphere));
  }
}

// The <mesh filename> of a relative path (plain or file://), written relative to
// `output_directory` instead of `source_directory` (both absolute); package:// and absolute
// paths name the same file from anywhere and stay as they are.
void RewriteRelativeMeshPaths(XMLElement& root, const std::string& source_directory,
                              const std::string& output_directory) {
  namespace fs = std::filesystem;
  const fs::path source = fs::path(source_directory).lexically_normal();
  const fs::path output = fs::path(output_directory).lexically_normal();
  if (source == output) return;
  for (XMLElement* link = root.FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    for (XMLElement* part = link->FirstChildElement(); part != nullptr;
         part = part->NextSiblingElement()) {
      XMLElement* geometry = part->FirstChildElement("geometry");
      XMLElement* mesh = geometry == nullptr ? nullptr : geometry->FirstChildElement("mesh");
      const char* filename = mesh == nullptr ? nullptr : mesh->Attribute("filename");
      if (filename == nullptr) continue;
      std::string path = filename;
      std::string scheme;
      if (absl::StartsWith(path, "file://")) {
        scheme = "file://";
        path = path.substr(scheme.size());
      } else if (path.find("://") != std::string::npos) {
        continue;
      }
      if (path.empty() || fs::path(path).is_absolute()) continue;
      const fs::path relative = (source / path).lexically_normal().lexically_relative(output);
      if (relative.empty()) continue;  // different roots (not on POSIX paths)
      mesh->SetAttribute("filename", (scheme + relative.generic_string()).c_str());
    }
  }
}

}  // namespace

std::string ShortestDecimal(double value) {
  char buffer[64];
  const std::to_chars_result written = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, written.ptr);
}

absl::StatusOr<std::string> SpherizedUrdf(absl::string_view urdf_bytes,
                                          const std::vector<LinkSpherizeResult>& links,
                                          const std::string& source_directory,
                                          const std::string& output_directory) {
  XMLDocument document;
  if (document.Parse(urdf_bytes.data(), urdf_bytes.size()) != tinyxml2::XML_SUCCESS ||
      document.RootElement() == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("URDF line ", document.ErrorLineNum(), ": not well-formed XML"));
  }
  std::map<std::string, const LinkSpherizeResult*> by_name;
  for (const LinkSpherizeResult& result : links) by_name.emplace(result.link, &result);
  for (XMLElement* link = document.RootElement()->FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    const auto found = by_name.find(name == nullptr ? "" : name);
    if (found == by_name.end()) continue;
    const LinkSpherizeResult& result = *found->second;
    if (result.status == LinkStatus::kSpherized) {
      ReplaceCollisions(document, *link, result);
    } else if (result.status == LinkStatus::kSkipped) {
      link->InsertFirstChild(document.NewComment(
          CommentText(
              absl::StrCat("inscribe urdf: not spherized, geometry kept as it was: ", result.error))
              .c_str()));
    }
  }
  if (!source_directory.empty() && !output_directory.empty()) {
    RewriteRelativeMeshPaths(*document.RootElement(), source_directory, output_directory);
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return std::string(printer.CStr(), static_cast<std::size_t>(printer.CStrSize() - 1));
}

std::string SpherizedCuroboYaml(const std::vector<LinkSpherizeResult>& links,
                                const std::string& robot_name, std::vector<std::string>* left_out) {
  std::vector<LinkSpheres> spheres;
  for (const LinkSpherizeResult& result : links) {
    if (result.status != LinkStatus::kSpherized) continue;
    // The name alone decides: the spheres passed CheckSphere's rules when they were made.
    if (!FormatCuroboYaml({LinkSpheres{result.link, {}}}).ok()) {
      left_out->push_back(result.link);
      continue;
    }
    spheres.push_back({result.link, result.spheres});
  }
  // The robot's name goes into a comment line: no control character may end it early.
  std::string name = robot_name;
  for (char& c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  absl::StatusOr<std::string> yaml = FormatCuroboYaml(
      spheres, absl::StrCat("inscribe urdf", name.empty() ? "" : " of robot " + name,
                            ": collision spheres per link, link frames, metres"));
  // Only a bad name or a bad sphere is refused, and neither is left.
  assert(yaml.ok());
  return *std::move(yaml);
}

absl::StatusOr<std::string> SpherizedCuroboYaml(const std::vector<LinkSpherizeResult>& links,
                                                const std::string& robot_name,
                                                const SelfCollisionMatrix& matrix,
                                                const std::map<std::string, double>& buffers,
                                                std::vector<std::string>* left_out) {
  for (const auto& [link, buffer] : buffers) {
    if (!std::isfinite(buffer)) {
      return absl::InvalidArgumentError(
          absl::StrCat("self_collision_buffer of link '", link, "' is not finite"));
    }
  }
  const std::size_t left_before = left_out->size();
  std::string yaml = SpherizedCuroboYaml(links, robot_name, left_out);
  const std::set<std::string> left(left_out->begin() + static_cast<std::ptrdiff_t>(left_before),
                                   left_out->end());
  std::vector<std::string> written;
  for (const LinkSpherizeResult& result : links) {
    if (result.status == LinkStatus::kSpherized && left.count(result.link) == 0) {
      written.push_back(result.link);
    }
  }
  std::set<std::pair<std::string, std::string>> disabled;
  for (const LinkPairCollision& pair : matrix.pairs) {
    if (!CollisionDisabled(pair.type)) continue;
    disabled.emplace(matrix.links[pair.link_a], matrix.links[pair.link_b]);
    disabled.emplace(matrix.links[pair.link_b], matrix.links[pair.link_a]);
  }
  // Names are quoted as FormatCuroboYaml quotes them (plain keys such as `null` or `1` would
  // be read as other types); they hold only letters, digits and _ - . /.
  std::string ignore;
  for (std::size_t i = 0; i < written.size(); ++i) {
    std::vector<std::string> ignored;
    for (std::size_t j = i + 1; j < written.size(); ++j) {
      if (disabled.count({written[i], written[j]}) != 0) {
        ignored.push_back(absl::StrCat("\"", written[j], "\""));
      }
    }
    if (ignored.empty()) continue;
    absl::StrAppend(&ignore, "  \"", written[i], "\": [", absl::StrJoin(ignored, ", "), "]\n");
  }
  absl::StrAppend(&yaml, "self_collision_ignore:", ignore.empty() ? " {}\n" : "\n", ignore);
  absl::StrAppend(&yaml, "self_collision_buffer:", written.empty() ? " {}\n" : "\n");
  for (const std::string& link : written) {
    const auto found = buffers.find(link);
    // A YAML 1.1 float for PyYAML (cuRobo's loader): a '.' in the mantissa.
    std::string value = ShortestDecimal(found == buffers.end() ? 0.0 : found->second);
    if (value.find_first_of(".") == std::string::npos) {
      const std::size_t e = value.find_first_of("eE");
      value.insert(e == std::string::npos ? value.size() : e, ".0");
    }
    absl::StrAppend(&yaml, "  \"", link, "\": ", value, "\n");
  }
  return yaml;
}

}  // namespace inscribe::robot
