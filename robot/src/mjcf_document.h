// An MJCF document with its <include> elements replaced by the included files' contents, as
// plain nodes that remember the file and line they came from. Private to the MJCF reader.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace inscribe::robot::mjcf {

struct Node {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;  // in file order
  std::vector<Node> children;
  std::string file;  // relative to the model's folder, for messages
  int line = 0;

  // The attribute's value, or nullptr.
  const std::string* Attribute(absl::string_view attribute) const;
};

// "robot.xml line 12": where messages point.
std::string Where(const Node& node);

// The canonical path of `relative` (a path in the model, e.g. meshdir + file), taken from
// `folder` (canonical), when it lies inside `folder`; INVALID_ARGUMENT naming `what` otherwise.
// Never runs a shell; symbolic links are followed before the check.
absl::StatusOr<std::string> PathInside(const std::string& folder, const std::string& relative,
                                       const std::string& what);

// The <mujoco> root of `bytes` (the model file at `model_path`) with every <include file> in
// it and in the files it includes replaced, where it stood, by the children of the included
// file's <mujoco>. Files are read relative to the model's folder and only inside it.
// INVALID_ARGUMENT for what the reader refuses (see ParseMjcf). Also returns the folder.
struct Document {
  Node root;
  std::string folder;  // canonical, absolute
};
absl::StatusOr<Document> ReadDocument(absl::string_view bytes, const std::string& model_path);

}  // namespace inscribe::robot::mjcf
