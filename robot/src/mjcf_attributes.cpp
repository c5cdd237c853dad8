#include "mjcf_attributes.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "inscribe/robot/mjcf_orientation.h"

namespace inscribe::robot::mjcf {

absl::Status ErrorAt(const Node& node, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("MJCF ", mjcf::Where(node), ": ", what));
}

Attributes Resolve(const Node& node, const Attributes* defaults) {
  Attributes out;
  if (defaults != nullptr) out = *defaults;
  static const std::set<std::string> kOrientations = {"quat", "axisangle", "euler", "xyaxes",
                                                      "zaxis"};
  // An element's own orientation replaces its default's, whichever form either uses.
  const bool own_orientation =
      std::any_of(node.attributes.begin(), node.attributes.end(),
                  [](const auto& a) { return kOrientations.count(a.first); });
  if (own_orientation) {
    for (const std::string& name : kOrientations) out.erase(name);
  }
  for (const auto& [name, text] : node.attributes) out[name] = Value{text, &node};
  return out;
}

absl::Status AttributeError(const Value& value, const std::string& name, absl::string_view why) {
  return ErrorAt(*value.node,
                 absl::StrCat("<", value.node->name, " ", name, "=\"", value.text, "\">: ", why));
}

// Between `least` and `most` finite numbers from attribute `name`; nullopt when absent.
absl::StatusOr<std::optional<std::vector<double>>> Numbers(const Attributes& attributes,
                                                           const std::string& name, int least,
                                                           int most) {
  const auto it = attributes.find(name);
  if (it == attributes.end()) return std::optional<std::vector<double>>();
  const std::vector<absl::string_view> tokens =
      absl::StrSplit(it->second.text, absl::ByAnyChar(" \t\r\n"), absl::SkipEmpty());
  if (static_cast<int>(tokens.size()) < least || static_cast<int>(tokens.size()) > most) {
    return AttributeError(
        it->second, name,
        least == most
            ? absl::StrCat("expected ", least, least == 1 ? " number" : " numbers", ", found ",
                           tokens.size())
            : absl::StrCat("expected ", least, " to ", most, " numbers, found ", tokens.size()));
  }
  std::vector<double> values(tokens.size());
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    if (!absl::SimpleAtod(tokens[i], &values[i])) {
      return AttributeError(it->second, name, absl::StrCat("'", tokens[i], "' is not a number"));
    }
    if (!std::isfinite(values[i])) {
      return AttributeError(it->second, name, absl::StrCat("'", tokens[i], "' is not finite"));
    }
  }
  return std::optional<std::vector<double>>(std::move(values));
}

absl::StatusOr<Vector3> Vector(const Attributes& attributes, const std::string& name,
                               const Vector3& fallback) {
  absl::StatusOr<std::optional<std::vector<double>>> v = Numbers(attributes, name, 3, 3);
  if (!v.ok()) return v.status();
  if (!*v) return fallback;
  return Vector3((**v)[0], (**v)[1], (**v)[2]);
}

absl::StatusOr<int> Integer(const Attributes& attributes, const std::string& name, int fallback) {
  const auto it = attributes.find(name);
  if (it == attributes.end()) return fallback;
  int value = 0;
  if (!absl::SimpleAtoi(it->second.text, &value)) {
    return AttributeError(it->second, name, "not a whole number");
  }
  return value;
}

absl::StatusOr<bool> Boolean(const Attributes& attributes, const std::string& name, bool fallback) {
  const auto it = attributes.find(name);
  if (it == attributes.end()) return fallback;
  if (it->second.text == "true") return true;
  if (it->second.text == "false") return false;
  return AttributeError(it->second, name, "expected true or false");
}

std::string Text(const Attributes& attributes, const std::string& name,
                 const std::string& fallback) {
  const auto it = attributes.find(name);
  return it == attributes.end() ? fallback : it->second.text;
}

// The element's rotation from whichever of quat, axisangle, euler, xyaxes and zaxis it has
// (identity for none); two or more is an error, as in MuJoCo since 2.2.1.
absl::StatusOr<Eigen::Matrix3d> Orientation(const Attributes& attributes, const Node& node,
                                            const AngleSettings& angles) {
  std::vector<std::string> given;
  for (const char* name : {"quat", "axisangle", "euler", "xyaxes", "zaxis"}) {
    if (attributes.count(name)) given.push_back(name);
  }
  if (given.empty()) return Eigen::Matrix3d::Identity();
  if (given.size() > 1) {
    return ErrorAt(node, absl::StrCat("<", node.name, "> has several orientations (",
                                      absl::StrJoin(given, ", "), "); give one"));
  }
  const std::string& form = given[0];
  const Value& value = attributes.at(form);
  const int count = form == "quat" || form == "axisangle" ? 4 : form == "xyaxes" ? 6 : 3;
  absl::StatusOr<std::optional<std::vector<double>>> numbers =
      Numbers(attributes, form, count, count);
  if (!numbers.ok()) return numbers.status();
  const std::vector<double>& n = **numbers;
  const double angle_unit = angles.degrees ? M_PI / 180.0 : 1.0;
  absl::StatusOr<Eigen::Matrix3d> rotation;
  if (form == "quat") {
    rotation = MjcfQuatRotation(Eigen::Vector4d(n[0], n[1], n[2], n[3]));
  } else if (form == "axisangle") {
    rotation = MjcfAxisAngleRotation(Vector3(n[0], n[1], n[2]), n[3] * angle_unit);
  } else if (form == "euler") {
    rotation = MjcfEulerRotation(angle_unit * Vector3(n[0], n[1], n[2]), angles.eulerseq);
  } else if (form == "xyaxes") {
    rotation = MjcfXyAxesRotation(Vector3(n[0], n[1], n[2]), Vector3(n[3], n[4], n[5]));
  } else {
    rotation = MjcfZAxisRotation(Vector3(n[0], n[1], n[2]));
  }
  if (!rotation.ok()) return AttributeError(value, form, rotation.status().message());
  return *rotation;
}

}  // namespace inscribe::robot::mjcf
