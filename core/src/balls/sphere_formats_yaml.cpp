// cuRobo-style YAML collision spheres: a `collision_spheres:` mapping from link name to a list of
// {center: [x, y, z], radius: r}, the block cuRobo's robot configurations hold (directly, or in
// the separate sphere file they name). Written by hand (the layout cuRobo's own files use, one
// sphere per two lines, shortest round-trip numbers); read with yaml-cpp.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "balls/sphere_formats.h"

namespace inscribe {
namespace {

// A YAML 1.1 float (PyYAML's resolver, which cuRobo loads with, wants a '.' in the mantissa:
// "1e+22" would be a string, "1.0e+22" is a float), still the shortest round-trip digits.
std::string YamlDouble(double value) {
  std::string s = internal::FormatDouble(value);
  if (s.find('.') == std::string::npos) {
    const std::size_t e = s.find('e');
    s.insert(e == std::string::npos ? s.size() : e, ".0");
  }
  return s;
}

// "line L" (1-based) of a node, for messages.
std::string Where(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.line < 0 ? std::string("yaml") : absl::StrCat("line ", mark.line + 1);
}

// The scalar as a finite double, parsed exactly (yaml-cpp's own conversion goes through a
// stream); YAML's ".inf" / ".nan" and anything else that is not a decimal number are refused.
absl::StatusOr<double> FiniteNumber(const YAML::Node& node, absl::string_view what) {
  if (!node.IsScalar()) {
    return absl::InvalidArgumentError(absl::StrCat(Where(node), ": ", what, " is not a number"));
  }
  double value = 0.0;
  std::string why;
  if (!internal::ParseDouble(node.Scalar(), &value, &why) || !std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(Where(node), ": ", what, " ",
                                                   internal::QuoteToken(node.Scalar()),
                                                   " is not a finite number"));
  }
  return value;
}

// The first mapping under a `collision_spheres` key, searched breadth first from the root so a
// whole cuRobo robot file (robot_cfg: kinematics: collision_spheres:) works as well as a sphere
// file. A string there names another file, which the caller must read instead.
absl::StatusOr<YAML::Node> FindCollisionSpheres(const YAML::Node& root) {
  std::vector<YAML::Node> level = {root};
  for (int depth = 0; depth < 8 && !level.empty(); ++depth) {
    std::vector<YAML::Node> next;
    for (const YAML::Node& node : level) {
      if (!node.IsMap()) continue;
      for (const auto& entry : node) {
        if (entry.first.IsScalar() && entry.first.Scalar() == "collision_spheres") {
          const YAML::Node& value = entry.second;
          if (value.IsMap()) return value;
          if (value.IsScalar()) {
            return absl::InvalidArgumentError(
                absl::StrCat(Where(value), ": collision_spheres names another file ",
                             internal::QuoteToken(value.Scalar()), "; read that file instead"));
          }
          return absl::InvalidArgumentError(absl::StrCat(
              Where(value), ": collision_spheres is not a mapping from link names to spheres"));
        }
        if (entry.second.IsMap()) next.push_back(entry.second);
      }
    }
    level = std::move(next);
  }
  return absl::InvalidArgumentError("no collision_spheres mapping (cuRobo's link -> spheres)");
}

absl::StatusOr<std::vector<Sphere>> LinkSpheresFromYaml(const std::string& link,
                                                        const YAML::Node& list) {
  std::vector<Sphere> spheres;
  if (list.IsNull()) return spheres;
  if (!list.IsSequence()) {
    return absl::InvalidArgumentError(
        absl::StrCat(Where(list), ": link ", internal::QuoteToken(link), " is not a list"));
  }
  std::size_t index = 0;
  for (const YAML::Node& item : list) {
    const std::string what = absl::StrCat("link ", internal::QuoteToken(link), " sphere ", index);
    ++index;
    if (!item.IsMap() || !item["center"] || !item["radius"]) {
      return absl::InvalidArgumentError(
          absl::StrCat(Where(item), ": ", what, " needs center and radius"));
    }
    const YAML::Node center = item["center"];
    if (!center.IsSequence() || center.size() != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat(Where(center), ": ", what, " center is not a list of 3 numbers"));
    }
    Sphere sphere;
    for (int k = 0; k < 3; ++k) {
      absl::StatusOr<double> c = FiniteNumber(center[k], absl::StrCat(what, " center"));
      if (!c.ok()) return c.status();
      sphere.center[k] = *c;
    }
    absl::StatusOr<double> radius = FiniteNumber(item["radius"], absl::StrCat(what, " radius"));
    if (!radius.ok()) return radius.status();
    if (*radius <= 0.0) continue;  // cuRobo's placeholder spheres
    sphere.radius = *radius;
    spheres.push_back(sphere);
  }
  return spheres;
}

}  // namespace

bool IsCuroboLinkName(absl::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == '/';
  });
}

absl::StatusOr<std::string> FormatCuroboYaml(const std::vector<LinkSpheres>& links,
                                             absl::string_view comment) {
  std::set<std::string> seen;
  std::string out;
  for (absl::string_view line : absl::StrSplit(comment, '\n')) {
    absl::StrAppend(&out, "# ", line, "\n");
  }
  absl::StrAppend(&out, "collision_spheres:", links.empty() ? " {}\n" : "\n");
  for (const LinkSpheres& link : links) {
    if (!IsCuroboLinkName(link.link)) {
      return absl::InvalidArgumentError(
          absl::StrCat("yaml link name ", internal::QuoteToken(link.link),
                       " is not a non-empty run of letters, digits and _ - . /"));
    }
    if (!seen.insert(link.link).second) {
      return absl::InvalidArgumentError(absl::StrCat("link ", link.link, " is listed twice"));
    }
    for (std::size_t i = 0; i < link.spheres.size(); ++i) {
      if (absl::Status status = CheckSphere(link.spheres[i], i); !status.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("link ", link.link, ": ", status.message()));
      }
    }
    // Quoted: YAML resolves plain keys such as null, true, no, 1 or .inf to other types
    // (PyYAML, which cuRobo loads with, would hand it None, a bool or a number for a link
    // named so; found by fuzz_urdf). Link names need no escapes inside the quotes.
    absl::StrAppend(&out, "  \"", link.link, "\":", link.spheres.empty() ? " []\n" : "\n");
    for (const Sphere& s : link.spheres) {
      absl::StrAppend(&out, "    - \"center\": [", YamlDouble(s.center.x()), ", ",
                      YamlDouble(s.center.y()), ", ", YamlDouble(s.center.z()), "]\n",
                      "      \"radius\": ", YamlDouble(s.radius), "\n");
    }
  }
  return out;
}

absl::StatusOr<std::vector<LinkSpheres>> ParseCuroboYaml(absl::string_view bytes) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(bytes));
  } catch (const YAML::Exception& e) {
    return absl::InvalidArgumentError(
        e.mark.is_null() ? absl::StrCat("malformed YAML: ", e.msg)
                         : absl::StrCat("line ", e.mark.line + 1, ": malformed YAML: ", e.msg));
  }
  try {
    absl::StatusOr<YAML::Node> mapping = FindCollisionSpheres(root);
    if (!mapping.ok()) return mapping.status();
    std::vector<LinkSpheres> links;
    std::set<std::string> seen;
    for (const auto& entry : *mapping) {
      if (!entry.first.IsScalar() || entry.first.Scalar().empty()) {
        return absl::InvalidArgumentError(
            absl::StrCat(Where(entry.first), ": a link name is not a plain string"));
      }
      const std::string& name = entry.first.Scalar();
      if (!seen.insert(name).second) {
        return absl::InvalidArgumentError(absl::StrCat(
            Where(entry.first), ": link ", internal::QuoteToken(name), " is listed twice"));
      }
      absl::StatusOr<std::vector<Sphere>> spheres = LinkSpheresFromYaml(name, entry.second);
      if (!spheres.ok()) return spheres.status();
      links.push_back(LinkSpheres{name, *std::move(spheres)});
    }
    return links;
  } catch (const YAML::Exception& e) {  // a conversion yaml-cpp refuses inside a valid document
    return absl::InvalidArgumentError(absl::StrCat("malformed YAML: ", e.msg));
  }
}

namespace internal {

absl::StatusOr<SphereFile> ParseYamlSphereFile(absl::string_view bytes, const std::string& link) {
  absl::StatusOr<std::vector<LinkSpheres>> links = ParseCuroboYaml(bytes);
  if (!links.ok()) return links.status();
  std::vector<std::string> names;
  for (LinkSpheres& entry : *links) {
    if (link.empty() ? links->size() == 1 : entry.link == link) {
      SphereFile file;
      file.set.spheres = std::move(entry.spheres);
      return file;
    }
    names.push_back(entry.link);
  }
  if (names.empty()) return absl::InvalidArgumentError("collision_spheres lists no link");
  if (link.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        names.size(), " links (", absl::StrJoin(names, ", "), "): name the one to read (--link)"));
  }
  return absl::InvalidArgumentError(absl::StrCat("no link ", QuoteToken(link), " (the file has ",
                                                 absl::StrJoin(names, ", "), ")"));
}

std::string FormatYamlSphereFile(const SphereFile& file, const std::string& link_name) {
  std::string comment = absl::StrCat("inscribe spheres: ", file.set.spheres.size(), " spheres");
  if (!file.mesh_sha256.empty()) absl::StrAppend(&comment, ", mesh ", file.mesh_sha256);
  // The caller checked the link name and the spheres, the only things FormatCuroboYaml refuses.
  return *FormatCuroboYaml({LinkSpheres{link_name, file.set.spheres}}, comment);
}

}  // namespace internal
}  // namespace inscribe
