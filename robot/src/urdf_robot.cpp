#include "inscribe/robot/urdf_robot.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <system_error>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace inscribe::robot {
namespace {

namespace fs = std::filesystem;

using tinyxml2::XMLElement;

// How to turn a .xacro file into the URDF inscribe reads.
constexpr absl::string_view kExpandXacro =
    "expand the xacro file first: xacro robot.urdf.xacro > robot.urdf";

absl::Status ErrorAt(int line, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("URDF line ", line, ": ", what));
}

// " (OWNER)" for an owner such as "link 'base'" or "joint 'elbow'"; "" when it is not known.
std::string InOwner(const std::string& owner) {
  return owner.empty() ? "" : absl::StrCat(" (", owner, ")");
}

// `count` whitespace-separated finite numbers from attribute `name` of `element`; `fallback`
// when the attribute is absent and not `required`.
absl::StatusOr<std::vector<double>> ParseNumbers(const XMLElement& element, const char* name,
                                                 int count, bool required,
                                                 std::vector<double> fallback,
                                                 const std::string& link) {
  const tinyxml2::XMLAttribute* attribute = element.FindAttribute(name);
  if (attribute == nullptr) {
    if (!required) return fallback;
    return ErrorAt(element.GetLineNum(), absl::StrCat("<", element.Name(), "> has no ", name,
                                                      " attribute", InOwner(link)));
  }
  const std::string text = attribute->Value();
  const auto malformed = [&](absl::string_view why) {
    return ErrorAt(attribute->GetLineNum(), absl::StrCat("<", element.Name(), " ", name, "=\"",
                                                         text, "\">: ", why, InOwner(link)));
  };
  if (absl::StrContains(text, "${") || absl::StrContains(text, "$(")) {
    return malformed(absl::StrCat("unexpanded xacro expression; ", kExpandXacro));
  }
  const std::vector<absl::string_view> tokens =
      absl::StrSplit(text, absl::ByAnyChar(" \t\r\n"), absl::SkipEmpty());
  if (static_cast<int>(tokens.size()) != count) {
    return malformed(absl::StrCat("expected ", count, count == 1 ? " number" : " numbers",
                                  ", found ", tokens.size()));
  }
  std::vector<double> values(tokens.size());
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    if (!absl::SimpleAtod(tokens[i], &values[i])) {
      return malformed(absl::StrCat("'", tokens[i], "' is not a number"));
    }
    if (!std::isfinite(values[i])) {
      return malformed(absl::StrCat("'", tokens[i], "' is not finite"));
    }
  }
  return values;
}

absl::StatusOr<Vector3> ParseVector(const XMLElement& element, const char* name, bool required,
                                    const Vector3& fallback, const std::string& link) {
  absl::StatusOr<std::vector<double>> values =
      ParseNumbers(element, name, 3, required, {fallback.x(), fallback.y(), fallback.z()}, link);
  if (!values.ok()) return values.status();
  return Vector3((*values)[0], (*values)[1], (*values)[2]);
}

// One positive number, e.g. a radius (metres).
absl::StatusOr<double> ParsePositive(const XMLElement& element, const char* name,
                                     const std::string& link) {
  absl::StatusOr<std::vector<double>> values = ParseNumbers(element, name, 1, true, {}, link);
  if (!values.ok()) return values.status();
  if ((*values)[0] <= 0.0) {
    return ErrorAt(element.GetLineNum(),
                   absl::StrCat("<", element.Name(), "> ", name, " ", (*values)[0],
                                " is not positive", InOwner(link)));
  }
  return (*values)[0];
}

absl::StatusOr<UrdfOrigin> ParseOrigin(const XMLElement& element, const std::string& link) {
  UrdfOrigin origin;
  const XMLElement* node = element.FirstChildElement("origin");
  if (node == nullptr) return origin;
  absl::StatusOr<Vector3> xyz = ParseVector(*node, "xyz", false, Vector3::Zero(), link);
  if (!xyz.ok()) return xyz.status();
  absl::StatusOr<Vector3> rpy = ParseVector(*node, "rpy", false, Vector3::Zero(), link);
  if (!rpy.ok()) return rpy.status();
  origin.xyz = *xyz;
  origin.rpy = *rpy;
  return origin;
}

absl::StatusOr<UrdfGeometry> ParseGeometry(const XMLElement& element, const std::string& link) {
  UrdfGeometry geometry;
  const XMLElement* holder = element.FirstChildElement("geometry");
  const XMLElement* shape = holder == nullptr ? nullptr : holder->FirstChildElement();
  if (shape == nullptr) return geometry;  // kUnsupported, unsupported == ""
  const std::string kind = shape->Name();
  if (kind == "mesh") {
    const char* filename = shape->Attribute("filename");
    if (filename == nullptr || filename[0] == '\0') {
      return ErrorAt(shape->GetLineNum(),
                     absl::StrCat("<mesh> has no filename attribute", InOwner(link)));
    }
    absl::StatusOr<Vector3> scale = ParseVector(*shape, "scale", false, Vector3::Ones(), link);
    if (!scale.ok()) return scale.status();
    if ((scale->array() == 0.0).any()) {
      return ErrorAt(
          shape->GetLineNum(),
          absl::StrCat("<mesh scale> has a zero component: the mesh would be flat", InOwner(link)));
    }
    geometry.shape = UrdfShape::kMesh;
    geometry.filename = filename;
    geometry.scale = *scale;
  } else if (kind == "box") {
    absl::StatusOr<Vector3> size = ParseVector(*shape, "size", true, Vector3::Zero(), link);
    if (!size.ok()) return size.status();
    if (!(size->array() > 0.0).all()) {
      return ErrorAt(shape->GetLineNum(),
                     absl::StrCat("<box size> must be 3 positive numbers", InOwner(link)));
    }
    geometry.shape = UrdfShape::kBox;
    geometry.size = *size;
  } else if (kind == "cylinder") {
    absl::StatusOr<double> radius = ParsePositive(*shape, "radius", link);
    if (!radius.ok()) return radius.status();
    absl::StatusOr<double> length = ParsePositive(*shape, "length", link);
    if (!length.ok()) return length.status();
    geometry.shape = UrdfShape::kCylinder;
    geometry.radius = *radius;
    geometry.length = *length;
  } else if (kind == "capsule" || kind == "drake:capsule") {
    // As urdfdom's Capsule and Drake read it: `length` is the cylinder's, between the caps'
    // centres, along z.
    absl::StatusOr<double> radius = ParsePositive(*shape, "radius", link);
    if (!radius.ok()) return radius.status();
    absl::StatusOr<double> length = ParsePositive(*shape, "length", link);
    if (!length.ok()) return length.status();
    geometry.shape = UrdfShape::kCapsule;
    geometry.radius = *radius;
    geometry.length = *length;
  } else if (kind == "sphere") {
    absl::StatusOr<double> radius = ParsePositive(*shape, "radius", link);
    if (!radius.ok()) return radius.status();
    geometry.shape = UrdfShape::kSphere;
    geometry.radius = *radius;
  } else {
    geometry.unsupported = kind;
  }
  return geometry;
}

absl::StatusOr<UrdfElement> ParseElement(const XMLElement& element, const std::string& link) {
  UrdfElement parsed;
  parsed.line = element.GetLineNum();
  if (const char* name = element.Attribute("name"); name != nullptr) parsed.name = name;
  absl::StatusOr<UrdfOrigin> origin = ParseOrigin(element, link);
  if (!origin.ok()) return origin.status();
  parsed.origin = *origin;
  absl::StatusOr<UrdfGeometry> geometry = ParseGeometry(element, link);
  if (!geometry.ok()) return geometry.status();
  parsed.geometry = *std::move(geometry);
  return parsed;
}

std::string InJoint(const std::string& joint) {
  return InOwner(absl::StrCat("joint '", joint, "'"));
}

// One number from attribute `name`, `fallback` when it is absent.
absl::StatusOr<double> ParseNumber(const XMLElement& element, const char* name, double fallback,
                                   const std::string& where) {
  absl::StatusOr<std::vector<double>> values =
      ParseNumbers(element, name, 1, false, {fallback}, where);
  if (!values.ok()) return values.status();
  return (*values)[0];
}

std::optional<UrdfJointType> JointTypeFromName(absl::string_view name) {
  for (UrdfJointType type :
       {UrdfJointType::kFixed, UrdfJointType::kRevolute, UrdfJointType::kContinuous,
        UrdfJointType::kPrismatic, UrdfJointType::kFloating, UrdfJointType::kPlanar}) {
    if (name == UrdfJointTypeName(type)) return type;
  }
  return std::nullopt;
}

// The link attribute of <parent> or <child> (`kind`) of joint `element`.
absl::StatusOr<std::string> JointLink(const XMLElement& element, const char* kind,
                                      const std::string& joint) {
  const XMLElement* node = element.FirstChildElement(kind);
  if (node == nullptr) {
    return ErrorAt(element.GetLineNum(),
                   absl::StrCat("<joint> has no <", kind, "> element", InJoint(joint)));
  }
  const char* link = node->Attribute("link");
  if (link == nullptr || link[0] == '\0') {
    return ErrorAt(node->GetLineNum(),
                   absl::StrCat("<", kind, "> has no link attribute", InJoint(joint)));
  }
  return std::string(link);
}

absl::StatusOr<UrdfJoint> ParseJoint(const XMLElement& element) {
  UrdfJoint joint;
  joint.line = element.GetLineNum();
  const char* name = element.Attribute("name");
  if (name == nullptr || name[0] == '\0') {
    return ErrorAt(joint.line, "<joint> has no name attribute");
  }
  joint.name = name;
  const std::string in_joint = absl::StrCat("joint '", joint.name, "'");
  const char* type = element.Attribute("type");
  if (type == nullptr) {
    return ErrorAt(joint.line, absl::StrCat("<joint> has no type attribute", InJoint(joint.name)));
  }
  const std::optional<UrdfJointType> parsed_type = JointTypeFromName(type);
  if (!parsed_type) {
    return ErrorAt(joint.line,
                   absl::StrCat("<joint type=\"", type,
                                "\"> is not a URDF joint type (fixed, revolute, continuous, "
                                "prismatic, floating, planar)",
                                InJoint(joint.name)));
  }
  joint.type = *parsed_type;
  absl::StatusOr<std::string> parent = JointLink(element, "parent", joint.name);
  if (!parent.ok()) return parent.status();
  absl::StatusOr<std::string> child = JointLink(element, "child", joint.name);
  if (!child.ok()) return child.status();
  joint.parent = *std::move(parent);
  joint.child = *std::move(child);
  absl::StatusOr<UrdfOrigin> origin = ParseOrigin(element, in_joint);
  if (!origin.ok()) return origin.status();
  joint.origin = *origin;

  const bool has_axis =
      joint.type != UrdfJointType::kFixed && joint.type != UrdfJointType::kFloating;
  if (const XMLElement* axis = element.FirstChildElement("axis"); axis != nullptr && has_axis) {
    absl::StatusOr<Vector3> xyz = ParseVector(*axis, "xyz", false, Vector3::UnitX(), in_joint);
    if (!xyz.ok()) return xyz.status();
    const double norm = xyz->norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      return ErrorAt(axis->GetLineNum(),
                     absl::StrCat("<axis xyz> of a ", type, " joint is zero (or overflows)",
                                  InJoint(joint.name)));
    }
    joint.axis = *xyz / norm;
  }

  const bool limited =
      joint.type == UrdfJointType::kRevolute || joint.type == UrdfJointType::kPrismatic;
  if (const XMLElement* limit = element.FirstChildElement("limit"); limit != nullptr) {
    absl::StatusOr<double> lower = ParseNumber(*limit, "lower", 0.0, in_joint);
    if (!lower.ok()) return lower.status();
    absl::StatusOr<double> upper = ParseNumber(*limit, "upper", 0.0, in_joint);
    if (!upper.ok()) return upper.status();
    if (limited && *lower > *upper) {
      return ErrorAt(limit->GetLineNum(),
                     absl::StrCat("<limit lower=\"", *lower, "\" upper=\"", *upper,
                                  "\">: lower > upper", InJoint(joint.name)));
    }
    joint.lower = *lower;
    joint.upper = *upper;
  }

  if (const XMLElement* mimic = element.FirstChildElement("mimic"); mimic != nullptr) {
    const char* of = mimic->Attribute("joint");
    if (of == nullptr || of[0] == '\0') {
      return ErrorAt(mimic->GetLineNum(),
                     absl::StrCat("<mimic> has no joint attribute", InJoint(joint.name)));
    }
    UrdfMimic parsed;
    parsed.joint = of;
    absl::StatusOr<double> multiplier = ParseNumber(*mimic, "multiplier", 1.0, in_joint);
    if (!multiplier.ok()) return multiplier.status();
    absl::StatusOr<double> offset = ParseNumber(*mimic, "offset", 0.0, in_joint);
    if (!offset.ok()) return offset.status();
    parsed.multiplier = *multiplier;
    parsed.offset = *offset;
    joint.mimic = std::move(parsed);
  }
  return joint;
}

// The prefix ("xacro:", or whatever the root binds to the xacro namespace URI) that marks
// xacro elements.
std::string XacroPrefix(const XMLElement& root) {
  for (const tinyxml2::XMLAttribute* a = root.FirstAttribute(); a != nullptr; a = a->Next()) {
    if (absl::StartsWith(a->Name(), "xmlns:") && absl::StrContains(a->Value(), "wiki/xacro")) {
      return absl::StrCat(absl::StripPrefix(a->Name(), "xmlns:"), ":");
    }
  }
  return "xacro:";
}

// The first element, in document order, whose name has the xacro `prefix`.
const XMLElement* FindXacro(const XMLElement& element, const std::string& prefix) {
  if (absl::StartsWith(element.Name(), prefix) || absl::StartsWith(element.Name(), "xacro:")) {
    return &element;
  }
  for (const XMLElement* child = element.FirstChildElement(); child != nullptr;
       child = child->NextSiblingElement()) {
    if (const XMLElement* found = FindXacro(*child, prefix); found != nullptr) return found;
  }
  return nullptr;
}

absl::StatusOr<UrdfLink> ParseLink(const XMLElement& element) {
  UrdfLink link;
  link.line = element.GetLineNum();
  const char* name = element.Attribute("name");
  if (name == nullptr || name[0] == '\0') {
    return ErrorAt(link.line, "<link> has no name attribute");
  }
  link.name = name;
  for (const char* kind : {"collision", "visual"}) {
    for (const XMLElement* child = element.FirstChildElement(kind); child != nullptr;
         child = child->NextSiblingElement(kind)) {
      absl::StatusOr<UrdfElement> parsed =
          ParseElement(*child, absl::StrCat("link '", link.name, "'"));
      if (!parsed.ok()) return parsed.status();
      link.elements.push_back(*std::move(parsed));
    }
    if (!link.elements.empty()) {
      link.from_visual = std::string(kind) == "visual";
      break;
    }
  }
  return link;
}

// The first '&' in `text` that does not start a reference tinyxml2 reads correctly (&lt;
// &gt; &amp; &quot; &apos; &#...;), as the text from it to the next ';' or at most 12 bytes;
// empty when there is none.
std::string UnknownEntity(absl::string_view text) {
  for (std::size_t at = text.find('&'); at != absl::string_view::npos;
       at = text.find('&', at + 1)) {
    const absl::string_view rest = text.substr(at + 1);
    bool known = absl::StartsWith(rest, "#");
    for (const char* name : {"lt;", "gt;", "amp;", "quot;", "apos;"}) {
      known = known || absl::StartsWith(rest, name);
    }
    if (!known) {
      const std::size_t semicolon = text.find(';', at);
      const std::size_t length = semicolon == absl::string_view::npos ? 12 : semicolon - at + 1;
      return std::string(text.substr(at, std::min<std::size_t>(length, 12)));
    }
  }
  return "";
}

// Every attribute value and text of `element` and below (of a document read without entity
// processing) must use only the entities XML has without a DTD, which tinyxml2 does not read.
absl::Status CheckEntities(const XMLElement& element) {
  for (const tinyxml2::XMLAttribute* a = element.FirstAttribute(); a != nullptr; a = a->Next()) {
    if (const std::string entity = UnknownEntity(a->Value()); !entity.empty()) {
      return ErrorAt(a->GetLineNum(),
                     absl::StrCat("<", element.Name(), " ", a->Name(), ">: '", entity,
                                  "' is not an XML entity (write a literal & as &amp;)"));
    }
  }
  for (const tinyxml2::XMLNode* child = element.FirstChild(); child != nullptr;
       child = child->NextSibling()) {
    if (const tinyxml2::XMLText* text = child->ToText(); text != nullptr && !text->CData()) {
      if (const std::string entity = UnknownEntity(text->Value()); !entity.empty()) {
        return ErrorAt(text->GetLineNum(),
                       absl::StrCat("text in <", element.Name(), ">: '", entity,
                                    "' is not an XML entity (write a literal & as &amp;)"));
      }
    } else if (const XMLElement* inner = child->ToElement(); inner != nullptr) {
      if (absl::Status status = CheckEntities(*inner); !status.ok()) return status;
    }
  }
  return absl::OkStatus();
}

// What tinyxml2 accepts but XML does not, on `bytes` that tinyxml2 parsed: text or another
// element beside the root (the writer would print them back where tinyxml2 itself then refuses
// the output, and a second <robot> would be ignored without a word), and unknown entities
// (tinyxml2 9 turns one into stale bytes of the value, silently: the writer would print
// garbage, e.g. into joint names). All found by fuzz_urdf. Read again without entity
// processing, the only way to see the entities as written.
absl::Status CheckStrictXml(absl::string_view bytes) {
  tinyxml2::XMLDocument raw(/*processEntities=*/false);
  raw.Parse(bytes.data(), bytes.size());
  const XMLElement* root = raw.RootElement();
  for (const tinyxml2::XMLNode* node = raw.FirstChild(); node != nullptr;
       node = node->NextSibling()) {
    if (node->ToText() != nullptr) {
      return ErrorAt(node->GetLineNum(),
                     absl::StrCat("not well-formed XML: text '",
                                  absl::StripAsciiWhitespace(node->Value()).substr(0, 40),
                                  "' outside the root element <robot>"));
    }
    if (node->ToElement() != nullptr && node != root) {
      return ErrorAt(node->GetLineNum(),
                     absl::StrCat("not well-formed XML: a second top-level element <",
                                  node->Value(), "> (a URDF has one root element, <robot>)"));
    }
  }
  return root == nullptr ? absl::OkStatus() : CheckEntities(*root);
}

bool IsDirectory(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error);
}

bool IsFile(const fs::path& path) {
  std::error_code error;
  return fs::exists(path, error) && !fs::is_directory(path, error);
}

// The last component of a directory path, "/a/pkg/" and "/a/pkg" alike.
std::string DirectoryName(const fs::path& directory) {
  const fs::path normal = directory.lexically_normal();
  return (normal.has_filename() ? normal : normal.parent_path()).filename().string();
}

std::vector<std::string> SplitPathList(const char* value) {
  if (value == nullptr) return {};
  return absl::StrSplit(value, ':', absl::SkipEmpty());
}

absl::StatusOr<std::string> ExistingFile(const fs::path& path, const std::string& filename) {
  if (IsFile(path)) return path.lexically_normal().string();
  return absl::NotFoundError(absl::StrCat("mesh file ", path.lexically_normal().string(),
                                          " (from '", filename, "') does not exist"));
}

absl::StatusOr<std::string> ResolvePackageUri(absl::string_view rest, const std::string& filename,
                                              const PackageSearch& search) {
  const std::size_t slash = rest.find('/');
  const std::string package(rest.substr(0, slash));
  const std::string relative(slash == absl::string_view::npos ? "" : rest.substr(slash + 1));
  if (package.empty() || relative.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("'", filename, "' is not package://PACKAGE/PATH"));
  }
  std::vector<std::string> looked;
  std::optional<fs::path> found;
  for (const std::vector<std::string>* list : {&search.package_paths, &search.ros_package_path}) {
    for (const std::string& directory : *list) {
      const fs::path d(directory);
      if (IsDirectory(d / package)) {
        found = d / package;
      } else if (DirectoryName(d) == package && IsDirectory(d)) {
        found = d;
      }
      if (found) break;
      looked.push_back(directory);
    }
    if (found) break;
  }
  if (!found) {
    for (const std::string& prefix : search.ament_prefix_path) {
      const fs::path d = fs::path(prefix) / "share" / package;
      if (IsDirectory(d)) {
        found = d;
        break;
      }
      looked.push_back((fs::path(prefix) / "share").string());
    }
  }
  if (!found) {
    return absl::NotFoundError(absl::StrCat(
        "package '", package, "' (of '", filename, "') not found; looked in ",
        looked.empty() ? std::string("no directory (give --package-path or set ROS_PACKAGE_PATH)")
                       : absl::StrJoin(looked, ", ")));
  }
  return ExistingFile(*found / relative, filename);
}

}  // namespace

const char* UrdfJointTypeName(UrdfJointType type) {
  switch (type) {
    case UrdfJointType::kFixed:
      return "fixed";
    case UrdfJointType::kRevolute:
      return "revolute";
    case UrdfJointType::kContinuous:
      return "continuous";
    case UrdfJointType::kPrismatic:
      return "prismatic";
    case UrdfJointType::kFloating:
      return "floating";
    case UrdfJointType::kPlanar:
      return "planar";
  }
  return "unknown";
}

Eigen::Matrix3d RotationFromRpy(const Vector3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vector3::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Vector3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vector3::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d OriginRotation(const UrdfOrigin& origin) {
  return origin.rotation ? *origin.rotation : RotationFromRpy(origin.rpy);
}

std::string DescribeUrdfElement(const UrdfElement& element, bool from_visual) {
  std::string text =
      absl::StrCat("line ", element.line, " (<", from_visual ? "visual" : "collision", ">");
  if (!element.name.empty()) absl::StrAppend(&text, " '", element.name, "'");
  return text + ")";
}

absl::StatusOr<UrdfRobot> ParseUrdf(absl::string_view bytes) {
  if (const std::size_t nul = bytes.find('\0'); nul != absl::string_view::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("URDF byte ", nul, " is NUL: this is not an XML text file"));
  }
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    return ErrorAt(document.ErrorLineNum(),
                   absl::StrCat("not well-formed XML: ", document.ErrorName()));
  }
  const XMLElement* root = document.RootElement();
  if (root == nullptr)
    return absl::InvalidArgumentError("URDF has no root element: not an XML document");
  if (std::string(root->Name()) != "robot") {
    return ErrorAt(root->GetLineNum(),
                   absl::StrCat("the root element is <", root->Name(), ">, not <robot>"));
  }
  if (absl::Status strict = CheckStrictXml(bytes); !strict.ok()) return strict;
  if (const XMLElement* xacro = FindXacro(*root, XacroPrefix(*root)); xacro != nullptr) {
    return ErrorAt(xacro->GetLineNum(),
                   absl::StrCat("<", xacro->Name(), "> is unexpanded xacro; ", kExpandXacro));
  }
  UrdfRobot robot;
  if (const char* name = root->Attribute("name"); name != nullptr) robot.name = name;
  std::set<std::string> names;
  for (const XMLElement* element = root->FirstChildElement("link"); element != nullptr;
       element = element->NextSiblingElement("link")) {
    absl::StatusOr<UrdfLink> link = ParseLink(*element);
    if (!link.ok()) return link.status();
    if (!names.insert(link->name).second) {
      return ErrorAt(link->line, absl::StrCat("link name '", link->name, "' is used twice"));
    }
    robot.links.push_back(*std::move(link));
  }
  for (const XMLElement* element = root->FirstChildElement("joint"); element != nullptr;
       element = element->NextSiblingElement("joint")) {
    absl::StatusOr<UrdfJoint> joint = ParseJoint(*element);
    if (!joint.ok()) return joint.status();
    robot.joints.push_back(*std::move(joint));
  }
  return robot;
}

PackageSearch PackageSearchFromEnvironment(std::vector<std::string> package_paths) {
  PackageSearch search;
  search.package_paths = std::move(package_paths);
  search.ros_package_path = SplitPathList(std::getenv("ROS_PACKAGE_PATH"));
  search.ament_prefix_path = SplitPathList(std::getenv("AMENT_PREFIX_PATH"));
  return search;
}

absl::StatusOr<std::string> ResolveMeshFilename(const std::string& filename,
                                                const std::string& urdf_dir,
                                                const PackageSearch& search) {
  absl::string_view rest = filename;
  if (absl::ConsumePrefix(&rest, "package://")) {
    return ResolvePackageUri(rest, filename, search);
  }
  if (absl::ConsumePrefix(&rest, "file://")) {
    // file:///abs/path has an empty authority; file://relative is taken as relative.
  } else if (const std::size_t scheme = filename.find("://"); scheme != std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("mesh '", filename, "': URI scheme '", filename.substr(0, scheme),
                     "' is not supported (use package://, file:// or a path)"));
  }
  if (rest.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("mesh '", filename, "' has an empty path"));
  }
  const fs::path path(std::string{rest});
  return ExistingFile(path.is_absolute() ? path : fs::path(urdf_dir) / path, filename);
}

}  // namespace inscribe::robot
