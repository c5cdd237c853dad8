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
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/robot_spheres.h"
#include "robot_spheres_formats.h"

namespace inscribe::robot {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;
using tinyxml2::XMLNode;

// The YAML's header comment. The robot's name goes into a comment line: no control character
// may end it early.
std::string CuroboComment(const std::string& robot_name) {
  std::string name = robot_name;
  for (char& c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return absl::StrCat("inscribe urdf", name.empty() ? "" : " of robot " + name,
                      ": collision spheres per link, link frames, metres");
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
      internal::ReplaceLinkCollisions(
          document, *link, result.spheres,
          absl::StrCat("inscribe urdf: ", result.spheres.size(), " spheres in place of the link's ",
                       result.from_visual ? "visual" : "collision", " geometry"));
    } else if (result.status == LinkStatus::kSkipped) {
      link->InsertFirstChild(document.NewComment(
          internal::XmlCommentText(
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
    if (!IsCuroboLinkName(result.link)) {
      left_out->push_back(result.link);
      continue;
    }
    spheres.push_back({result.link, result.spheres});
  }
  absl::StatusOr<std::string> yaml = FormatCuroboYaml(spheres, CuroboComment(robot_name));
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
  // The model of the links written, each with a buffer (0 when absent), and the pairs among
  // them `matrix` disables.
  std::vector<LinkSpherizeResult> written;
  std::map<std::string, double> written_buffers;
  for (const LinkSpherizeResult& result : links) {
    if (result.status != LinkStatus::kSpherized) continue;
    if (!IsCuroboLinkName(result.link)) {
      left_out->push_back(result.link);
    } else {
      written.push_back(result);
      const auto found = buffers.find(result.link);
      written_buffers[result.link] = found == buffers.end() ? 0.0 : found->second;
    }
  }
  RobotSpheres model = RobotSpheresFromSpherized(written, robot_name, &matrix, written_buffers);
  for (auto it = model.self_collision_ignore.begin(); it != model.self_collision_ignore.end();) {
    const bool both =
        written_buffers.count(it->first.first) != 0 && written_buffers.count(it->first.second) != 0;
    it = both ? std::next(it) : model.self_collision_ignore.erase(it);
  }
  RobotSpheresWriteOptions options;
  options.comment = CuroboComment(robot_name);
  return FormatRobotSpheres(model, RobotSpheresFormat::kCurobo, options);
}

}  // namespace inscribe::robot
