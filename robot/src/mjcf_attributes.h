// Reading MJCF attributes, an element's own over its default class's, with errors naming the
// file, line, element and attribute where the value is written. Private to the MJCF reader.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/mesh.h"
#include "mjcf_document.h"

namespace inscribe::robot::mjcf {

// INVALID_ARGUMENT "MJCF FILE line N: what".
absl::Status ErrorAt(const Node& node, absl::string_view what);

// An attribute's value and the element it is written on (the element itself or a default).
struct Value {
  std::string text;
  const Node* node = nullptr;
};
using Attributes = std::map<std::string, Value>;  // by attribute name

// The attributes of `node` over `defaults` (a class's for the node's kind; may be null). An
// element's own orientation replaces its default's, whichever form either uses.
Attributes Resolve(const Node& node, const Attributes* defaults);

// "MJCF FILE line N: <ELEMENT NAME="TEXT">: why", at the element the value is written on.
absl::Status AttributeError(const Value& value, const std::string& name, absl::string_view why);

// Between `least` and `most` finite numbers from attribute `name`; nullopt when absent.
absl::StatusOr<std::optional<std::vector<double>>> Numbers(const Attributes& attributes,
                                                           const std::string& name, int least,
                                                           int most);
// Three numbers, `fallback` when absent.
absl::StatusOr<Vector3> Vector(const Attributes& attributes, const std::string& name,
                               const Vector3& fallback);
absl::StatusOr<int> Integer(const Attributes& attributes, const std::string& name, int fallback);
// "true" or "false".
absl::StatusOr<bool> Boolean(const Attributes& attributes, const std::string& name, bool fallback);
std::string Text(const Attributes& attributes, const std::string& name,
                 const std::string& fallback = "");

// <compiler angle eulerseq>: how orientations' angles are read.
struct AngleSettings {
  bool degrees = true;  // MuJoCo's default
  std::string eulerseq = "xyz";
};

// The element's rotation from whichever of quat, axisangle, euler, xyaxes and zaxis it has
// (identity for none); two or more is an error, as in MuJoCo since 2.2.1.
absl::StatusOr<Eigen::Matrix3d> Orientation(const Attributes& attributes, const Node& node,
                                            const AngleSettings& angles);

}  // namespace inscribe::robot::mjcf
