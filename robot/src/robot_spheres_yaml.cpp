// cuRobo's robot configuration fragment and cuMotion's XRDF 1.0: written by hand (quoted keys,
// one sphere per two lines, shortest round-trip numbers with a '.' so PyYAML reads floats), read
// with yaml-cpp. cuRobo's collision_spheres block is core's (FormatCuroboYaml, ParseCuroboYaml).
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "inscribe/robot/spherized_urdf.h"
#include "robot_spheres_formats.h"

namespace inscribe::robot::internal {
namespace {

using PairMap = std::map<std::pair<std::string, std::string>, std::string>;

// A YAML 1.1 float for PyYAML (cuRobo's loader): a '.' in the mantissa ("1e-05" would be a
// string, "1.0e-05" is a float).
std::string YamlFloat(double value) {
  std::string text = ShortestDecimal(value);
  if (text.find('.') == std::string::npos) {
    const std::size_t e = text.find_first_of("eE");
    text.insert(e == std::string::npos ? text.size() : e, ".0");
  }
  return text;
}

std::string Quoted(const std::string& name) { return absl::StrCat("\"", name, "\""); }

// Every name the document will hold as a key or list item.
absl::Status CheckYamlNames(const RobotSpheres& model, const char* format) {
  auto check = [&](const std::string& name) -> absl::Status {
    if (IsCuroboLinkName(name)) return absl::OkStatus();
    return absl::InvalidArgumentError(absl::StrCat(format, " cannot carry the link name '", name,
                                                   "' (letters, digits and _ - . / only)"));
  };
  for (const LinkSpheres& link : model.links) {
    if (absl::Status s = check(link.link); !s.ok()) return s;
  }
  for (const auto& [pair, reason] : model.self_collision_ignore) {
    if (absl::Status s = check(pair.first); !s.ok()) return s;
    if (absl::Status s = check(pair.second); !s.ok()) return s;
  }
  for (const auto* buffers : {&model.self_collision_buffer, &model.collision_buffer}) {
    for (const auto& [link, value] : *buffers) {
      if (absl::Status s = check(link); !s.ok()) return s;
    }
  }
  return absl::OkStatus();
}

void AppendComment(const std::string& comment, std::string* out) {
  for (absl::string_view line : absl::StrSplit(comment, '\n')) {
    absl::StrAppend(out, "# ", line, "\n");
  }
}

// `indent` + one "name": value line per buffer, or " {}" after the key when there are none.
void AppendBufferMap(const std::map<std::string, double>& buffers, const std::string& indent,
                     std::string* out) {
  absl::StrAppend(out, buffers.empty() ? " {}\n" : "\n");
  for (const auto& [link, value] : buffers) {
    absl::StrAppend(out, indent, Quoted(link), ": ", YamlFloat(value), "\n");
  }
}

// The pairs grouped under their first link, in name order.
void AppendIgnore(const PairMap& pairs, const std::string& indent, std::string* out) {
  absl::StrAppend(out, pairs.empty() ? " {}\n" : "\n");
  for (auto it = pairs.begin(); it != pairs.end();) {
    const std::string& first = it->first.first;
    std::vector<std::string> seconds;
    for (; it != pairs.end() && it->first.first == first; ++it) {
      seconds.push_back(Quoted(it->first.second));
    }
    absl::StrAppend(out, indent, Quoted(first), ": [", absl::StrJoin(seconds, ", "), "]\n");
  }
}

// "line L" of a node (1-based), for messages.
std::string Where(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.line < 0 ? std::string("yaml") : absl::StrCat("line ", mark.line + 1);
}

absl::Status Error(const YAML::Node& node, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat(Where(node), ": ", what));
}

absl::StatusOr<YAML::Node> LoadYaml(absl::string_view bytes) {
  try {
    return YAML::Load(std::string(bytes));
  } catch (const YAML::Exception& e) {
    return absl::InvalidArgumentError(
        e.mark.is_null() ? absl::StrCat("malformed YAML: ", e.msg)
                         : absl::StrCat("line ", e.mark.line + 1, ": malformed YAML: ", e.msg));
  }
}

absl::StatusOr<std::string> NameOf(const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar() || node.Scalar().empty()) {
    return Error(node, absl::StrCat(what, " is not a link name"));
  }
  return node.Scalar();
}

absl::StatusOr<double> FiniteNumber(const YAML::Node& node, const std::string& what) {
  double value = 0.0;
  if (!node.IsScalar() || !absl::SimpleAtod(node.Scalar(), &value) || !std::isfinite(value)) {
    return Error(node, absl::StrCat(what, " is not a finite number"));
  }
  return value;
}

// {link: number}, or (scalar_for_all) one number for every link of `links`.
absl::Status ReadBuffers(const YAML::Node& node, const std::string& key,
                         const std::vector<LinkSpheres>* scalar_for_all,
                         std::map<std::string, double>* buffers) {
  if (!node || node.IsNull()) return absl::OkStatus();
  if (node.IsScalar() && scalar_for_all != nullptr) {
    absl::StatusOr<double> value = FiniteNumber(node, key);
    if (!value.ok()) return value.status();
    for (const LinkSpheres& link : *scalar_for_all) (*buffers)[link.link] = *value;
    return absl::OkStatus();
  }
  if (!node.IsMap()) {
    return Error(node, absl::StrCat(key, " is not a mapping from link names to metres"));
  }
  for (const auto& entry : node) {
    absl::StatusOr<std::string> link = NameOf(entry.first, key + " key");
    if (!link.ok()) return link.status();
    absl::StatusOr<double> value =
        FiniteNumber(entry.second, absl::StrCat(key, " of link '", *link, "'"));
    if (!value.ok()) return value.status();
    if (!buffers->emplace(*link, *value).second) {
      return Error(entry.first, absl::StrCat(key, " lists link '", *link, "' twice"));
    }
  }
  return absl::OkStatus();
}

// {link: [other, ...]}: each pair once, ordered.
absl::Status ReadIgnore(const YAML::Node& node, const std::string& key, PairMap* pairs) {
  if (!node || node.IsNull()) return absl::OkStatus();
  if (!node.IsMap()) return Error(node, key + " is not a mapping from link names to lists");
  for (const auto& entry : node) {
    absl::StatusOr<std::string> link = NameOf(entry.first, key + " key");
    if (!link.ok()) return link.status();
    if (entry.second.IsNull()) continue;
    if (!entry.second.IsSequence()) {
      return Error(entry.second, absl::StrCat(key, " of link '", *link, "' is not a list"));
    }
    for (const YAML::Node& item : entry.second) {
      absl::StatusOr<std::string> other =
          NameOf(item, absl::StrCat("an item of ", key, " of link '", *link, "'"));
      if (!other.ok()) return other.status();
      if (*other == *link) {
        return Error(item, absl::StrCat(key, ": link '", *link, "' ignores itself"));
      }
      (*pairs)[std::minmax(*link, *other)] = "";
    }
  }
  return absl::OkStatus();
}

// The mapping holding `key`, breadth first from the root (a fragment, or a whole robot file
// with robot_cfg: kinematics:), as core's ParseCuroboYaml looks for collision_spheres.
YAML::Node FindParentOf(const YAML::Node& root, const std::string& key) {
  std::vector<YAML::Node> level = {root};
  for (int depth = 0; depth < 8 && !level.empty(); ++depth) {
    std::vector<YAML::Node> next;
    for (const YAML::Node& node : level) {
      if (!node.IsMap()) continue;
      if (node[key]) return node;
      for (const auto& entry : node) {
        if (entry.second.IsMap()) next.push_back(entry.second);
      }
    }
    level = std::move(next);
  }
  return YAML::Node();
}

// XRDF's geometry.<group>.spheres: {link: [{center: [x, y, z], radius: r}, ...]}, radii > 0.
absl::Status ReadXrdfSpheres(const YAML::Node& spheres, const std::string& group,
                             std::vector<LinkSpheres>* links) {
  const std::string where = absl::StrCat("geometry '", group, "' spheres");
  if (!spheres || !spheres.IsMap()) {
    return Error(spheres ? spheres : YAML::Node(),
                 where + " is missing or not a mapping from link names to lists");
  }
  std::set<std::string> seen;
  for (const auto& entry : spheres) {
    absl::StatusOr<std::string> link = NameOf(entry.first, where + " key");
    if (!link.ok()) return link.status();
    if (!seen.insert(*link).second) {
      return Error(entry.first, absl::StrCat(where, " lists link '", *link, "' twice"));
    }
    LinkSpheres out{*link, {}};
    if (!entry.second.IsNull()) {
      if (!entry.second.IsSequence()) {
        return Error(entry.second, absl::StrCat("link '", *link, "' spheres are not a list"));
      }
      std::size_t index = 0;
      for (const YAML::Node& item : entry.second) {
        const std::string what = absl::StrCat("link '", *link, "' sphere ", index++);
        if (!item.IsMap() || !item["center"] || !item["radius"]) {
          return Error(item, what + " needs center and radius");
        }
        const YAML::Node center = item["center"];
        if (!center.IsSequence() || center.size() != 3) {
          return Error(center, what + " center is not a list of 3 numbers");
        }
        Sphere sphere;
        for (int k = 0; k < 3; ++k) {
          absl::StatusOr<double> c = FiniteNumber(center[k], what + " center");
          if (!c.ok()) return c.status();
          sphere.center[k] = *c;
        }
        absl::StatusOr<double> radius = FiniteNumber(item["radius"], what + " radius");
        if (!radius.ok()) return radius.status();
        if (!(*radius > 0.0)) return Error(item["radius"], what + " radius is not positive");
        sphere.radius = *radius;
        out.spheres.push_back(sphere);
      }
    }
    links->push_back(std::move(out));
  }
  return absl::OkStatus();
}

// The group a section (collision, self_collision) names, or "" when it names none.
absl::StatusOr<std::string> SectionGeometry(const YAML::Node& section, const char* name) {
  if (!section || section.IsNull()) return std::string();
  if (!section.IsMap()) return Error(section, absl::StrCat(name, " is not a mapping"));
  const YAML::Node geometry = section["geometry"];
  if (!geometry) return std::string();
  if (!geometry.IsScalar() || geometry.Scalar().empty()) {
    return Error(geometry, absl::StrCat(name, ".geometry is not a geometry group's name"));
  }
  return geometry.Scalar();
}

}  // namespace

bool IsXrdfDocument(absl::string_view bytes) {
  try {
    const YAML::Node root = YAML::Load(std::string(bytes));
    return root.IsMap() && root["format"] && root["format"].IsScalar() &&
           root["format"].Scalar() == "xrdf";
  } catch (const YAML::Exception&) {
    return false;
  }
}

absl::StatusOr<std::string> FormatCuroboRobotSpheres(const RobotSpheres& model,
                                                     const RobotSpheresWriteOptions& options) {
  if (absl::Status names = CheckYamlNames(model, "cuRobo YAML"); !names.ok()) return names;
  std::string out;
  std::vector<std::string> names;
  for (const LinkSpheres& link : model.links) names.push_back(Quoted(link.link));
  absl::StatusOr<std::string> spheres = FormatCuroboYaml(
      model.links, options.comment.empty() ? "cuRobo robot_cfg.kinematics keys; link frames, metres"
                                           : options.comment);
  if (!spheres.ok()) return spheres.status();
  // The comment, then collision_link_names, then FormatCuroboYaml's collision_spheres.
  const std::size_t body = spheres->find("collision_spheres:");
  absl::StrAppend(&out, spheres->substr(0, body), "collision_link_names: [",
                  absl::StrJoin(names, ", "), "]\n", spheres->substr(body));
  // One number when every link has the same world buffer (cuRobo takes a float or a mapping).
  if (!model.collision_buffer.empty()) {
    const double first = model.collision_buffer.begin()->second;
    bool uniform = model.collision_buffer.size() == model.links.size() && !model.links.empty();
    for (const LinkSpheres& link : model.links) {
      const auto found = model.collision_buffer.find(link.link);
      uniform = uniform && found != model.collision_buffer.end() && found->second == first;
    }
    absl::StrAppend(&out, "collision_sphere_buffer:");
    if (uniform) {
      absl::StrAppend(&out, " ", YamlFloat(first), "\n");
    } else {
      AppendBufferMap(model.collision_buffer, "  ", &out);
    }
  }
  absl::StrAppend(&out, "self_collision_ignore:");
  AppendIgnore(model.self_collision_ignore, "  ", &out);
  absl::StrAppend(&out, "self_collision_buffer:");
  AppendBufferMap(model.self_collision_buffer, "  ", &out);
  return out;
}

absl::StatusOr<RobotSpheres> ParseCuroboRobotSpheres(absl::string_view bytes) {
  absl::StatusOr<std::vector<LinkSpheres>> links = ParseCuroboYaml(bytes);
  if (!links.ok()) return links.status();
  absl::StatusOr<YAML::Node> root = LoadYaml(bytes);
  if (!root.ok()) return root.status();
  RobotSpheres model;
  model.links = *std::move(links);
  try {
    const YAML::Node kinematics = FindParentOf(*root, "collision_spheres");
    const YAML::Node names = kinematics["collision_link_names"];
    if (names && !names.IsNull()) {
      if (!names.IsSequence()) return Error(names, "collision_link_names is not a list");
      for (const YAML::Node& name : names) {
        if (absl::StatusOr<std::string> n = NameOf(name, "an item of collision_link_names");
            !n.ok()) {
          return n.status();
        }
      }
    }
    if (absl::Status s =
            ReadBuffers(kinematics["collision_sphere_buffer"], "collision_sphere_buffer",
                        &model.links, &model.collision_buffer);
        !s.ok()) {
      return s;
    }
    if (absl::Status s = ReadBuffers(kinematics["self_collision_buffer"], "self_collision_buffer",
                                     nullptr, &model.self_collision_buffer);
        !s.ok()) {
      return s;
    }
    if (absl::Status s = ReadIgnore(kinematics["self_collision_ignore"], "self_collision_ignore",
                                    &model.self_collision_ignore);
        !s.ok()) {
      return s;
    }
  } catch (const YAML::Exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("malformed YAML: ", e.msg));
  }
  return model;
}

absl::StatusOr<std::string> FormatXrdfRobotSpheres(const RobotSpheres& model,
                                                   const RobotSpheresWriteOptions& options) {
  if (absl::Status names = CheckYamlNames(model, "XRDF"); !names.ok()) return names;
  if (!IsCuroboLinkName(options.xrdf_geometry)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "XRDF geometry group name '", options.xrdf_geometry, "' is not letters, digits, _ - . /"));
  }
  std::string out;
  AppendComment(options.comment.empty() ? "cuMotion XRDF; link frames, metres" : options.comment,
                &out);
  const std::string group = Quoted(options.xrdf_geometry);
  absl::StrAppend(&out, "format: xrdf\nformat_version: 1.0\n\n");
  absl::StrAppend(&out, "collision:\n  geometry: ", group, "\n  buffer_distance:");
  AppendBufferMap(model.collision_buffer, "    ", &out);
  absl::StrAppend(&out, "\nself_collision:\n  geometry: ", group, "\n  buffer_distance:");
  AppendBufferMap(model.self_collision_buffer, "    ", &out);
  absl::StrAppend(&out, "  ignore:");
  AppendIgnore(model.self_collision_ignore, "    ", &out);
  absl::StrAppend(&out, "\ngeometry:\n  ", group,
                  ":\n    spheres:", model.links.empty() ? " {}\n" : "\n");
  for (const LinkSpheres& link : model.links) {
    absl::StrAppend(&out, "      ", Quoted(link.link), ":", link.spheres.empty() ? " []\n" : "\n");
    for (const Sphere& s : link.spheres) {
      absl::StrAppend(&out, "        - center: [", YamlFloat(s.center.x()), ", ",
                      YamlFloat(s.center.y()), ", ", YamlFloat(s.center.z()), "]\n",
                      "          radius: ", YamlFloat(s.radius), "\n");
    }
  }
  return out;
}

absl::StatusOr<RobotSpheres> ParseXrdfRobotSpheres(absl::string_view bytes) {
  absl::StatusOr<YAML::Node> root = LoadYaml(bytes);
  if (!root.ok()) return root.status();
  const YAML::Node doc = *root;  // const: lookups never add keys
  RobotSpheres model;
  try {
    if (!doc.IsMap()) return Error(doc, "an XRDF document is a mapping");
    const YAML::Node format = doc["format"];
    if (!format || !format.IsScalar() || format.Scalar() != "xrdf") {
      return Error(format ? format : doc, "format is not xrdf (an XRDF starts `format: xrdf`)");
    }
    const YAML::Node version = doc["format_version"];
    double number = 0.0;
    if (!version || !version.IsScalar() || !absl::SimpleAtod(version.Scalar(), &number) ||
        !(number >= 1.0 && number < 2.0)) {
      return Error(version ? version : doc,
                   "format_version is not 1.x (this reader knows XRDF 1.0)");
    }
    const YAML::Node collision = doc["collision"];
    const YAML::Node self_collision = doc["self_collision"];
    absl::StatusOr<std::string> world = SectionGeometry(collision, "collision");
    if (!world.ok()) return world.status();
    absl::StatusOr<std::string> self = SectionGeometry(self_collision, "self_collision");
    if (!self.ok()) return self.status();
    if (!world->empty() && !self->empty() && *world != *self) {
      return Error(self_collision["geometry"],
                   absl::StrCat("collision uses geometry '", *world, "' but self_collision '",
                                *self, "': one sphere set per robot is supported"));
    }
    const std::string group = !world->empty() ? *world : *self;
    if (!group.empty()) {
      const YAML::Node geometry = doc["geometry"];
      if (!geometry || !geometry.IsMap() || !geometry[group]) {
        return Error(geometry ? geometry : doc,
                     absl::StrCat("geometry has no group '", group, "'"));
      }
      const YAML::Node entry = geometry[group];
      if (!entry.IsMap())
        return Error(entry, absl::StrCat("geometry '", group, "' is not a mapping"));
      if (absl::Status s = ReadXrdfSpheres(entry["spheres"], group, &model.links); !s.ok()) {
        return s;
      }
    }
    if (collision && collision.IsMap()) {
      if (absl::Status s = ReadBuffers(collision["buffer_distance"], "collision.buffer_distance",
                                       nullptr, &model.collision_buffer);
          !s.ok()) {
        return s;
      }
    }
    if (self_collision && self_collision.IsMap()) {
      if (absl::Status s =
              ReadBuffers(self_collision["buffer_distance"], "self_collision.buffer_distance",
                          nullptr, &model.self_collision_buffer);
          !s.ok()) {
        return s;
      }
      if (absl::Status s = ReadIgnore(self_collision["ignore"], "self_collision.ignore",
                                      &model.self_collision_ignore);
          !s.ok()) {
        return s;
      }
    }
  } catch (const YAML::Exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("malformed YAML: ", e.msg));
  }
  return model;
}

}  // namespace inscribe::robot::internal
