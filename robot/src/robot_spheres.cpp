// The robot sphere model: format names and detection, what each format carries, the checks
// every writer shares, dispatch, and the model made from `inscribe urdf`'s results. The formats
// themselves are in robot_spheres_yaml.cpp, robot_spheres_srdf.cpp and robot_spheres_urdf.cpp.
#include "inscribe/robot/robot_spheres.h"

#include <tinyxml2.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "inscribe/robot/robot_file.h"
#include "robot_spheres_formats.h"

namespace inscribe::robot {
namespace {

bool SameSpheres(const std::vector<Sphere>& a, const std::vector<Sphere>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].center != b[i].center || a[i].radius != b[i].radius) return false;
  }
  return true;
}

absl::Status CheckBuffers(const std::map<std::string, double>& buffers, const char* key) {
  for (const auto& [link, value] : buffers) {
    if (link.empty())
      return absl::InvalidArgumentError(absl::StrCat(key, " of an empty link name"));
    if (!std::isfinite(value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(key, " of link '", link, "' is ", value, ", not a finite number"));
    }
  }
  return absl::OkStatus();
}

std::string Plural(std::size_t n, const char* what) {
  return absl::StrCat(n, " ", what, n == 1 ? "" : "s");
}

}  // namespace

bool operator==(const RobotSpheres& a, const RobotSpheres& b) {
  if (a.robot_name != b.robot_name || a.links.size() != b.links.size() ||
      a.self_collision_ignore != b.self_collision_ignore ||
      a.self_collision_buffer != b.self_collision_buffer ||
      a.collision_buffer != b.collision_buffer) {
    return false;
  }
  for (std::size_t l = 0; l < a.links.size(); ++l) {
    if (a.links[l].link != b.links[l].link || !SameSpheres(a.links[l].spheres, b.links[l].spheres))
      return false;
  }
  return true;
}

const char* RobotSpheresFormatName(RobotSpheresFormat format) {
  switch (format) {
    case RobotSpheresFormat::kCurobo:
      return "curobo";
    case RobotSpheresFormat::kXrdf:
      return "xrdf";
    case RobotSpheresFormat::kSrdf:
      return "srdf";
    case RobotSpheresFormat::kUrdf:
      return "urdf";
    case RobotSpheresFormat::kMorphit:
      return "morphit";
  }
  return "?";
}

absl::StatusOr<RobotSpheresFormat> ParseRobotSpheresFormat(absl::string_view name) {
  const std::string lower = absl::AsciiStrToLower(name);
  if (lower == "curobo" || lower == "yaml" || lower == "yml") return RobotSpheresFormat::kCurobo;
  if (lower == "xrdf") return RobotSpheresFormat::kXrdf;
  if (lower == "srdf") return RobotSpheresFormat::kSrdf;
  if (lower == "urdf" || lower == "vamp") return RobotSpheresFormat::kUrdf;
  if (lower == "morphit") return RobotSpheresFormat::kMorphit;
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown robot sphere format '", name, "' (expected curobo, xrdf, srdf, urdf or morphit)"));
}

absl::StatusOr<RobotSpheresFormat> RobotSpheresFormatFromPath(const std::string& path) {
  const std::string extension =
      absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  if (extension == ".yml" || extension == ".yaml") return RobotSpheresFormat::kCurobo;
  if (extension == ".xrdf") return RobotSpheresFormat::kXrdf;
  if (extension == ".srdf") return RobotSpheresFormat::kSrdf;
  if (extension == ".urdf") return RobotSpheresFormat::kUrdf;
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": cannot tell the robot sphere format from the extension '", extension,
                   "' (expected .yml, .yaml, .xrdf, .srdf or .urdf)"));
}

absl::StatusOr<RobotSpheresFormat> DetectRobotSpheresFormat(absl::string_view bytes) {
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) == tinyxml2::XML_SUCCESS &&
      document.RootElement() != nullptr) {
    const tinyxml2::XMLElement* root = document.RootElement();
    if (std::string(root->Name()) != "robot") {
      return absl::InvalidArgumentError(absl::StrCat(
          "an XML document whose root is <", root->Name(), ">, not <robot> (URDF or SRDF)"));
    }
    if (root->FirstChildElement("link") == nullptr) return RobotSpheresFormat::kSrdf;
    return internal::HasMorphitSphereLinks(bytes) ? RobotSpheresFormat::kMorphit
                                                  : RobotSpheresFormat::kUrdf;
  }
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first != absl::string_view::npos && bytes[first] == '<') {
    return absl::InvalidArgumentError(
        absl::StrCat("line ", document.ErrorLineNum(), ": not well-formed XML (URDF or SRDF)"));
  }
  return internal::IsXrdfDocument(bytes) ? RobotSpheresFormat::kXrdf : RobotSpheresFormat::kCurobo;
}

RobotSpheresFormatParts RobotSpheresFormatCarries(RobotSpheresFormat format) {
  RobotSpheresFormatParts parts;
  switch (format) {
    case RobotSpheresFormat::kCurobo:
    case RobotSpheresFormat::kXrdf:
      parts.empty_links = parts.pairs = parts.buffers = true;
      break;
    case RobotSpheresFormat::kSrdf:
      parts.robot_name = parts.empty_links = parts.pairs = parts.pair_reasons = true;
      break;
    case RobotSpheresFormat::kUrdf:
    case RobotSpheresFormat::kMorphit:
      parts.robot_name = true;
      break;
  }
  return parts;
}

std::vector<std::string> RobotSpheresDropped(const RobotSpheres& model, RobotSpheresFormat format) {
  const RobotSpheresFormatParts parts = RobotSpheresFormatCarries(format);
  std::vector<std::string> dropped;
  if (!parts.empty_links) {
    std::size_t empty = 0;
    for (const LinkSpheres& link : model.links) empty += link.spheres.empty();
    if (empty > 0) dropped.push_back(Plural(empty, "link") + " without spheres");
  }
  if (!parts.pairs && !model.self_collision_ignore.empty()) {
    dropped.push_back("self_collision_ignore (" +
                      Plural(model.self_collision_ignore.size(), "pair") + ")");
  } else if (parts.pairs && !parts.pair_reasons) {
    std::size_t reasons = 0;
    for (const auto& [pair, reason] : model.self_collision_ignore) reasons += !reason.empty();
    if (reasons > 0) dropped.push_back("the reasons of " + Plural(reasons, "ignored pair"));
  }
  if (!parts.buffers) {
    if (!model.self_collision_buffer.empty()) {
      dropped.push_back("self_collision_buffer (" +
                        Plural(model.self_collision_buffer.size(), "link") + ")");
    }
    if (!model.collision_buffer.empty()) {
      dropped.push_back("collision_sphere_buffer (" +
                        Plural(model.collision_buffer.size(), "link") + ")");
    }
  }
  if (!parts.robot_name && !model.robot_name.empty()) {
    dropped.push_back("the robot's name (a comment only)");
  }
  return dropped;
}

RobotSpheres RobotSpheresCarried(RobotSpheres model, RobotSpheresFormat format) {
  const RobotSpheresFormatParts parts = RobotSpheresFormatCarries(format);
  if (!parts.robot_name) model.robot_name.clear();
  if (!parts.empty_links) {
    std::vector<LinkSpheres> kept;
    for (LinkSpheres& link : model.links) {
      if (!link.spheres.empty()) kept.push_back(std::move(link));
    }
    model.links = std::move(kept);
  }
  if (!parts.pairs) model.self_collision_ignore.clear();
  if (!parts.pair_reasons) {
    for (auto& [pair, reason] : model.self_collision_ignore) reason.clear();
  }
  if (!parts.buffers) {
    model.self_collision_buffer.clear();
    model.collision_buffer.clear();
  }
  return model;
}

absl::Status CheckRobotSpheres(const RobotSpheres& model) {
  std::set<std::string> seen;
  for (const LinkSpheres& link : model.links) {
    if (link.link.empty()) return absl::InvalidArgumentError("a link with an empty name");
    if (!seen.insert(link.link).second) {
      return absl::InvalidArgumentError(absl::StrCat("link '", link.link, "' is listed twice"));
    }
    for (std::size_t i = 0; i < link.spheres.size(); ++i) {
      if (absl::Status status = CheckSphere(link.spheres[i], i); !status.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("link '", link.link, "': ", status.message()));
      }
    }
  }
  for (const auto& [pair, reason] : model.self_collision_ignore) {
    if (pair.first.empty() || pair.second.empty()) {
      return absl::InvalidArgumentError("an ignored pair with an empty link name");
    }
    if (!(pair.first < pair.second)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "ignored pair ('", pair.first, "', '", pair.second, "') ",
          pair.first == pair.second ? "pairs a link with itself" : "is not ordered (a < b)"));
    }
  }
  if (absl::Status s = CheckBuffers(model.self_collision_buffer, "self_collision_buffer");
      !s.ok()) {
    return s;
  }
  return CheckBuffers(model.collision_buffer, "collision_sphere_buffer");
}

absl::StatusOr<std::string> FormatRobotSpheres(const RobotSpheres& model, RobotSpheresFormat format,
                                               const RobotSpheresWriteOptions& options) {
  if (absl::Status checked = CheckRobotSpheres(model); !checked.ok()) return checked;
  switch (format) {
    case RobotSpheresFormat::kCurobo:
      return internal::FormatCuroboRobotSpheres(model, options);
    case RobotSpheresFormat::kXrdf:
      return internal::FormatXrdfRobotSpheres(model, options);
    case RobotSpheresFormat::kSrdf:
      return internal::FormatSrdfRobotSpheres(model, options);
    case RobotSpheresFormat::kUrdf:
    case RobotSpheresFormat::kMorphit:
      return internal::FormatUrdfRobotSpheres(model, format == RobotSpheresFormat::kMorphit,
                                              options);
  }
  return absl::InvalidArgumentError("unknown robot sphere format");
}

absl::StatusOr<RobotSpheres> ParseRobotSpheres(absl::string_view bytes, RobotSpheresFormat format) {
  switch (format) {
    case RobotSpheresFormat::kCurobo:
      return internal::ParseCuroboRobotSpheres(bytes);
    case RobotSpheresFormat::kXrdf:
      return internal::ParseXrdfRobotSpheres(bytes);
    case RobotSpheresFormat::kSrdf:
      return internal::ParseSrdfRobotSpheres(bytes);
    case RobotSpheresFormat::kUrdf:
    case RobotSpheresFormat::kMorphit:
      return internal::ParseUrdfRobotSpheres(bytes);
  }
  return absl::InvalidArgumentError("unknown robot sphere format");
}

absl::StatusOr<RobotSpheres> ReadRobotSpheresFile(const std::string& path,
                                                  std::optional<RobotSpheresFormat> format,
                                                  RobotSpheresFormat* read_as) {
  absl::StatusOr<std::string> bytes = ReadRobotFileBytes(path);
  if (!bytes.ok()) return bytes.status();
  if (!format) {
    absl::StatusOr<RobotSpheresFormat> by_extension = RobotSpheresFormatFromPath(path);
    // .yml may hold XRDF and .urdf either layout: the content tells those apart.
    if (by_extension.ok() && (*by_extension == RobotSpheresFormat::kXrdf ||
                              *by_extension == RobotSpheresFormat::kSrdf)) {
      format = *by_extension;
    } else {
      absl::StatusOr<RobotSpheresFormat> by_content = DetectRobotSpheresFormat(*bytes);
      if (!by_content.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat(path, ": ", by_content.status().message(), "; name the format"));
      }
      format = *by_content;
    }
  }
  absl::StatusOr<RobotSpheres> model = ParseRobotSpheres(*bytes, *format);
  if (!model.ok()) {
    return absl::Status(
        model.status().code(),
        absl::StrCat(path, " (", RobotSpheresFormatName(*format), "): ", model.status().message()));
  }
  if (read_as != nullptr) *read_as = *format;
  return model;
}

RobotSpheres RobotSpheresFromSpherized(const std::vector<LinkSpherizeResult>& links,
                                       const std::string& robot_name,
                                       const SelfCollisionMatrix* matrix,
                                       const std::map<std::string, double>& self_collision_buffer) {
  RobotSpheres model;
  model.robot_name = robot_name;
  for (const LinkSpherizeResult& result : links) {
    if (result.status == LinkStatus::kSpherized) {
      model.links.push_back(LinkSpheres{result.link, result.spheres});
    }
  }
  if (matrix != nullptr) {
    for (const LinkPairCollision& pair : matrix->pairs) {
      if (!CollisionDisabled(pair.type)) continue;
      std::string a = matrix->links[pair.link_a], b = matrix->links[pair.link_b];
      if (b < a) std::swap(a, b);
      model.self_collision_ignore[{a, b}] = CollisionPairClassName(pair.type);
    }
  }
  model.self_collision_buffer = self_collision_buffer;
  return model;
}

}  // namespace inscribe::robot
