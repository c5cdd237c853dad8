#include "mjcf_document.h"

#include <tinyxml2.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace inscribe::robot::mjcf {
namespace {

namespace fs = std::filesystem;

// Larger files are refused before reading (MJCF files are kilobytes to a few megabytes).
constexpr std::uintmax_t kMaxFileBytes = 256u << 20;
// Deeper nesting of includes than this is taken for a mistake.
constexpr int kMaxIncludeDepth = 64;

struct Reader {
  std::string folder;              // canonical
  std::set<std::string> included;  // canonical paths read so far
  std::vector<std::string> stack;  // the chain of includes being read
};

absl::Status ErrorIn(const std::string& file, int line, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("MJCF ", file, " line ", line, ": ", what));
}

absl::Status Convert(Reader& reader, const tinyxml2::XMLElement& element, const std::string& file,
                     Node* out);

// The children of `element` into `out`, includes replaced by what they include.
absl::Status ConvertChildren(Reader& reader, const tinyxml2::XMLElement& element,
                             const std::string& file, std::vector<Node>* out);

absl::Status Include(Reader& reader, const tinyxml2::XMLElement& element, const std::string& file,
                     std::vector<Node>* out) {
  const char* name = element.Attribute("file");
  if (name == nullptr || name[0] == '\0') {
    return ErrorIn(file, element.GetLineNum(), "<include> has no file attribute");
  }
  absl::StatusOr<std::string> path =
      PathInside(reader.folder, name, absl::StrCat("<include file=\"", name, "\">"));
  if (!path.ok()) return ErrorIn(file, element.GetLineNum(), path.status().message());
  if (std::find(reader.stack.begin(), reader.stack.end(), *path) != reader.stack.end()) {
    return ErrorIn(
        file, element.GetLineNum(),
        absl::StrCat("<include file=\"", name, "\"> includes itself (a cycle of includes)"));
  }
  if (!reader.included.insert(*path).second) {
    return ErrorIn(file, element.GetLineNum(),
                   absl::StrCat("<include file=\"", name,
                                "\">: the file is included twice (MuJoCo includes a file once)"));
  }
  if (static_cast<int>(reader.stack.size()) >= kMaxIncludeDepth) {
    return ErrorIn(file, element.GetLineNum(),
                   absl::StrCat("includes nest deeper than ", kMaxIncludeDepth));
  }
  std::error_code error;
  if (!fs::is_regular_file(*path, error)) {
    return ErrorIn(file, element.GetLineNum(),
                   absl::StrCat("<include file=\"", name, "\">: ", *path, " does not exist"));
  }
  if (fs::file_size(*path, error) > kMaxFileBytes) {
    return ErrorIn(file, element.GetLineNum(),
                   absl::StrCat("<include file=\"", name, "\">: the file is larger than ",
                                kMaxFileBytes, " bytes"));
  }
  std::ifstream in(*path, std::ios::binary);
  std::ostringstream contents;
  contents << in.rdbuf();
  if (!in) {
    return ErrorIn(file, element.GetLineNum(),
                   absl::StrCat("<include file=\"", name, "\">: ", *path, " cannot be read"));
  }
  const std::string bytes = contents.str();
  const std::string shown = fs::path(*path).lexically_relative(reader.folder).string();
  if (bytes.find('\0') != std::string::npos) {
    return ErrorIn(shown, 1, "a NUL byte: this is not an XML text file");
  }
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    return ErrorIn(shown, document.ErrorLineNum(),
                   absl::StrCat("not well-formed XML: ", document.ErrorName()));
  }
  const tinyxml2::XMLElement* root = document.RootElement();
  if (root == nullptr || std::string(root->Name()) != "mujoco") {
    return ErrorIn(shown, root == nullptr ? 1 : root->GetLineNum(),
                   "an included file's root element must be <mujoco>");
  }
  reader.stack.push_back(*path);
  absl::Status status = ConvertChildren(reader, *root, shown, out);
  reader.stack.pop_back();
  return status;
}

absl::Status ConvertChildren(Reader& reader, const tinyxml2::XMLElement& element,
                             const std::string& file, std::vector<Node>* out) {
  for (const tinyxml2::XMLElement* child = element.FirstChildElement(); child != nullptr;
       child = child->NextSiblingElement()) {
    if (std::string(child->Name()) == "include") {
      if (absl::Status s = Include(reader, *child, file, out); !s.ok()) return s;
      continue;
    }
    out->emplace_back();
    if (absl::Status s = Convert(reader, *child, file, &out->back()); !s.ok()) return s;
  }
  return absl::OkStatus();
}

absl::Status Convert(Reader& reader, const tinyxml2::XMLElement& element, const std::string& file,
                     Node* out) {
  out->name = element.Name();
  out->file = file;
  out->line = element.GetLineNum();
  for (const tinyxml2::XMLAttribute* a = element.FirstAttribute(); a != nullptr; a = a->Next()) {
    out->attributes.emplace_back(a->Name(), a->Value());
  }
  return ConvertChildren(reader, element, file, &out->children);
}

// Whether `path` is `folder` or lies below it (both canonical).
bool IsInside(const fs::path& path, const fs::path& folder) {
  auto p = path.begin();
  for (auto f = folder.begin(); f != folder.end(); ++f, ++p) {
    if (f->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *f) return false;
  }
  return true;
}

}  // namespace

const std::string* Node::Attribute(absl::string_view attribute) const {
  for (const auto& [key, value] : attributes) {
    if (key == attribute) return &value;
  }
  return nullptr;
}

std::string Where(const Node& node) { return absl::StrCat(node.file, " line ", node.line); }

absl::StatusOr<std::string> PathInside(const std::string& folder, const std::string& relative,
                                       const std::string& what) {
  if (relative.empty()) return absl::InvalidArgumentError(absl::StrCat(what, ": an empty path"));
  const fs::path given(relative);
  std::error_code error;
  const fs::path path = fs::weakly_canonical(fs::path(folder) / given, error);
  if (error || !IsInside(path, fs::path(folder))) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": '", relative, "' leads outside the model's folder ", folder,
                     "; files are read only inside it (copy the file into the folder)"));
  }
  return path.string();
}

absl::StatusOr<Document> ReadDocument(absl::string_view bytes, const std::string& model_path) {
  Reader reader;
  std::error_code error;
  const fs::path absolute = fs::absolute(model_path, error);
  reader.folder = fs::weakly_canonical(absolute.parent_path(), error).string();
  if (error) reader.folder = absolute.parent_path().lexically_normal().string();
  const std::string shown = absolute.filename().string();
  if (const std::size_t nul = bytes.find('\0'); nul != absl::string_view::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("MJCF ", shown, " byte ", nul, " is NUL: this is not an XML text file"));
  }
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    return ErrorIn(shown, document.ErrorLineNum(),
                   absl::StrCat("not well-formed XML: ", document.ErrorName()));
  }
  const tinyxml2::XMLElement* root = document.RootElement();
  if (root == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat("MJCF ", shown, " has no root element"));
  }
  if (std::string(root->Name()) != "mujoco") {
    return ErrorIn(shown, root->GetLineNum(),
                   absl::StrCat("the root element is <", root->Name(), ">, not <mujoco>"));
  }
  const std::string canonical = fs::weakly_canonical(absolute, error).string();
  reader.stack.push_back(canonical);
  reader.included.insert(canonical);
  Document out;
  out.folder = reader.folder;
  if (absl::Status s = Convert(reader, *root, shown, &out.root); !s.ok()) return s;
  return out;
}

}  // namespace inscribe::robot::mjcf
