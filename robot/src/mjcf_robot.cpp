#include "inscribe/robot/mjcf_robot.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <tuple>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "inscribe/robot/mjcf_orientation.h"
#include "mjcf_attributes.h"
#include "mjcf_document.h"
#include "mjcf_geoms.h"

namespace inscribe::robot {
namespace {

namespace fs = std::filesystem;
using mjcf::AngleSettings;
using mjcf::AttributeError;
using mjcf::Attributes;
using mjcf::Boolean;
using mjcf::ErrorAt;
using mjcf::MeshAsset;
using mjcf::Node;
using mjcf::Numbers;
using mjcf::Orientation;
using mjcf::Text;
using mjcf::Vector;

// A <default> class: per element kind (geom, joint, mesh), the attributes it sets, its
// ancestors' included.
struct DefaultClass {
  std::string name;
  int parent = -1;
  std::map<std::string, Attributes> kinds;
  const Attributes* Kind(const std::string& kind) const {
    const auto it = kinds.find(kind);
    return it == kinds.end() ? nullptr : &it->second;
  }
};

struct Compiler {
  AngleSettings angles;
  std::string meshdir;
  bool autolimits = true;  // MuJoCo's default since 2.3; 2.2.2 refuses range without limited
  bool strippath = false;
};

// `base`, or base_2, base_3, ... when taken; then taken.
std::string UniqueName(const std::string& base, std::set<std::string>* taken) {
  std::string name = base;
  for (int k = 2; !taken->insert(name).second; ++k) name = absl::StrCat(base, "_", k);
  return name;
}

// Every body name written under `node`.
void ReserveBodyNames(const Node& node, std::set<std::string>* names) {
  for (const Node& child : node.children) {
    if (child.name != "body") continue;
    if (const std::string* name = child.Attribute("name"); name != nullptr) names->insert(*name);
    ReserveBodyNames(child, names);
  }
}

class Reader {
 public:
  Reader(const mjcf::Document& document, const MjcfReadOptions& options)
      : document_(document), options_(options) {}

  absl::StatusOr<MjcfModel> Read();

 private:
  absl::Status ReadCompiler(const Node& node);
  absl::Status ReadDefault(const Node& node, int parent);
  absl::Status ReadMesh(const Node& node);
  absl::StatusOr<const DefaultClass*> ClassOf(const Node& node, const std::string& inherited);
  absl::Status ReadBody(const Node& node, int parent, const std::string& childclass);
  absl::Status ReadBodyChildren(const Node& node, int body, const std::string& childclass);
  absl::Status ReadJoint(const Node& node, int body, const std::string& childclass);
  absl::Status ReadGeom(const Node& node, int body, const std::string& childclass);
  void AddCoordinate(int body, const std::string& name, UrdfJointType type, const Vector3& axis,
                     const Vector3& anchor, double lower, double upper, int line, MjcfJoint* joint);
  void Finish();
  bool Selected(const MjcfGeom& geom) const;

  const mjcf::Document& document_;
  const MjcfReadOptions& options_;
  Compiler compiler_;
  bool meshdir_given_ = false;
  std::vector<DefaultClass> classes_;
  std::map<std::string, int> class_index_;
  std::map<std::string, MeshAsset> meshes_;
  MjcfModel model_;
  // Per body: its pose in its parent's frame, the frame its next joint starts from (the link
  // of the body's last coordinate so far) and its geoms and joints in file order.
  struct BodyState {
    UrdfOrigin pose;
    std::string frame_link;  // "" until a coordinate is added: the parent's link
    std::vector<MjcfGeom> geoms;
    std::vector<MjcfJoint> joints;
    std::vector<UrdfJoint> coordinates;
  };
  std::vector<BodyState> states_;
  std::set<std::string> link_names_, joint_names_, body_names_, written_joint_names_;
};

absl::Status Reader::ReadCompiler(const Node& node) {
  Attributes a = mjcf::Resolve(node, nullptr);
  if (const std::string angle = Text(a, "angle", "degree"); angle == "radian") {
    compiler_.angles.degrees = false;
  } else if (angle == "degree") {
    compiler_.angles.degrees = true;
  } else {
    return AttributeError(a.at("angle"), "angle", "expected degree or radian");
  }
  if (a.count("eulerseq")) {
    compiler_.angles.eulerseq = a.at("eulerseq").text;
    if (absl::StatusOr<Eigen::Matrix3d> check =
            MjcfEulerRotation(Vector3::Zero(), compiler_.angles.eulerseq);
        !check.ok()) {
      return AttributeError(a.at("eulerseq"), "eulerseq", check.status().message());
    }
  }
  // assetdir sets meshdir unless meshdir is given (in any <compiler>).
  if (a.count("meshdir")) {
    compiler_.meshdir = a.at("meshdir").text;
    meshdir_given_ = true;
  } else if (a.count("assetdir") && !meshdir_given_) {
    compiler_.meshdir = a.at("assetdir").text;
  }
  absl::StatusOr<bool> autolimits = Boolean(a, "autolimits", compiler_.autolimits);
  if (!autolimits.ok()) return autolimits.status();
  compiler_.autolimits = *autolimits;
  absl::StatusOr<bool> strippath = Boolean(a, "strippath", compiler_.strippath);
  if (!strippath.ok()) return strippath.status();
  compiler_.strippath = *strippath;
  if (const std::string coordinate = Text(a, "coordinate", "local"); coordinate != "local") {
    return AttributeError(a.at("coordinate"), "coordinate",
                          "only local coordinates are read (MuJoCo 2.3.3 dropped global ones "
                          "too); load and save the model with an older MuJoCo to convert it");
  }
  return absl::OkStatus();
}

absl::Status Reader::ReadDefault(const Node& node, int parent) {
  const std::string* name = node.Attribute("class");
  int index = 0;
  if (parent < 0) {
    // A top-level <default> is the class "main"; several add to it.
    if (name != nullptr && *name != "main") {
      return ErrorAt(node, absl::StrCat("the top-level <default class=\"", *name,
                                        "\">: this class is always \"main\"; nest "
                                        "<default class=\"",
                                        *name, "\"> inside it"));
    }
  } else {
    if (name == nullptr || name->empty()) {
      return ErrorAt(node, "a nested <default> has no class attribute");
    }
    if (class_index_.count(*name)) {
      return ErrorAt(node, absl::StrCat("default class '", *name, "' is defined twice"));
    }
    DefaultClass added = classes_[static_cast<std::size_t>(parent)];
    added.name = *name;
    added.parent = parent;
    index = static_cast<int>(classes_.size());
    class_index_[*name] = index;
    classes_.push_back(std::move(added));
  }
  // The class's own settings first, then its nested classes (which inherit all of them,
  // wherever they are written), as MuJoCo does.
  for (const Node& child : node.children) {
    if (child.name == "default") continue;
    Attributes& kind = classes_[static_cast<std::size_t>(index)].kinds[child.name];
    const Attributes own = mjcf::Resolve(child, nullptr);
    if (std::any_of(own.begin(), own.end(), [](const auto& a) {
          return a.first == "quat" || a.first == "axisangle" || a.first == "euler" ||
                 a.first == "xyaxes" || a.first == "zaxis";
        })) {
      for (const char* o : {"quat", "axisangle", "euler", "xyaxes", "zaxis"}) kind.erase(o);
    }
    for (const auto& [key, value] : own) kind[key] = value;
  }
  for (const Node& child : node.children) {
    if (child.name != "default") continue;
    if (absl::Status s = ReadDefault(child, index); !s.ok()) return s;
  }
  return absl::OkStatus();
}

absl::StatusOr<const DefaultClass*> Reader::ClassOf(const Node& node,
                                                    const std::string& inherited) {
  const std::string* own = node.Attribute("class");
  const std::string& name = own != nullptr ? *own : inherited;
  const auto it = class_index_.find(name);
  if (it == class_index_.end()) {
    return ErrorAt(node, absl::StrCat("<", node.name, " class=\"", name,
                                      "\">: no <default class=\"", name, "\"> defines it"));
  }
  return &classes_[static_cast<std::size_t>(it->second)];
}

absl::Status Reader::ReadMesh(const Node& node) {
  absl::StatusOr<const DefaultClass*> defaults = ClassOf(node, "main");
  if (!defaults.ok()) return defaults.status();
  const Attributes a = mjcf::Resolve(node, (*defaults)->Kind("mesh"));
  for (const char* inline_data : {"vertex", "face", "normal", "texcoord"}) {
    if (a.count(inline_data)) {
      return ErrorAt(node, absl::StrCat("<mesh ", inline_data,
                                        ">: meshes written inline are not read; give the mesh "
                                        "as a file (STL, OBJ)"));
    }
  }
  for (const char* reference : {"refpos", "refquat"}) {
    if (a.count(reference)) {
      return ErrorAt(node, absl::StrCat("<mesh ", reference,
                                        ">: reference frames of meshes are not read (MuJoCo 3 "
                                        "dropped them); move the vertices in the file instead"));
    }
  }
  const std::string file = Text(a, "file");
  if (file.empty()) return ErrorAt(node, "<mesh> has no file attribute");
  const std::string name = Text(a, "name", fs::path(file).stem().string());
  if (meshes_.count(name)) {
    return ErrorAt(node, absl::StrCat("mesh name '", name, "' is used twice"));
  }
  const std::string relative = compiler_.strippath ? fs::path(file).filename().string() : file;
  absl::StatusOr<std::string> path =
      mjcf::PathInside(document_.folder, (fs::path(compiler_.meshdir) / relative).string(),
                       absl::StrCat("<mesh file=\"", file, "\">"));
  if (!path.ok()) return ErrorAt(node, path.status().message());
  absl::StatusOr<Vector3> scale = Vector(a, "scale", Vector3::Ones());
  if (!scale.ok()) return scale.status();
  if ((scale->array() == 0.0).any()) {
    return AttributeError(a.at("scale"), "scale", "a zero component: the mesh would be flat");
  }
  meshes_[name] = MeshAsset{*path, *scale};
  return absl::OkStatus();
}

absl::Status Reader::ReadBody(const Node& node, int parent, const std::string& childclass) {
  const int index = static_cast<int>(model_.bodies.size());
  MjcfBody body;
  body.parent = parent;
  body.line = node.line;
  const std::string* name = node.Attribute("name");
  if (name != nullptr && !name->empty()) {
    if (*name == "world" || !body_names_.insert(*name).second) {
      return ErrorAt(node, absl::StrCat("body name '", *name, "' is used twice"));
    }
    body.name = *name;
  } else {
    // Every written name is reserved before any body is read: no later body loses its own.
    body.name = UniqueName(absl::StrCat("body", index), &link_names_);
  }
  const Attributes a = mjcf::Resolve(node, nullptr);
  BodyState state;
  absl::StatusOr<Vector3> pos = Vector(a, "pos", Vector3::Zero());
  if (!pos.ok()) return pos.status();
  absl::StatusOr<Eigen::Matrix3d> rotation = Orientation(a, node, compiler_.angles);
  if (!rotation.ok()) return rotation.status();
  state.pose.xyz = *pos;
  state.pose.rotation = *rotation;
  std::string inner = childclass;
  if (const std::string* own = node.Attribute("childclass"); own != nullptr) {
    if (!class_index_.count(*own)) {
      return ErrorAt(node, absl::StrCat("<body childclass=\"", *own, "\">: no <default class=\"",
                                        *own, "\"> defines it"));
    }
    inner = *own;
  }
  model_.bodies.push_back(std::move(body));
  states_.push_back(std::move(state));
  return ReadBodyChildren(node, index, inner);
}

absl::Status Reader::ReadBodyChildren(const Node& node, int body, const std::string& childclass) {
  for (const Node& child : node.children) {
    absl::Status status;
    if (child.name == "body") {
      status = ReadBody(child, body, childclass);
    } else if (child.name == "geom") {
      status = ReadGeom(child, body, childclass);
    } else if (child.name == "joint" || child.name == "freejoint") {
      if (body == 0) return ErrorAt(child, "the world body has no joints");
      status = ReadJoint(child, body, childclass);
    } else if (child.name == "frame") {
      status = ErrorAt(child, "<frame> (MuJoCo 3) is not read; move its pose into its children");
    }
    if (!status.ok()) return status;
  }
  return absl::OkStatus();
}

void Reader::AddCoordinate(int body, const std::string& name, UrdfJointType type,
                           const Vector3& axis, const Vector3& anchor, double lower, double upper,
                           int line, MjcfJoint* joint) {
  BodyState& state = states_[static_cast<std::size_t>(body)];
  UrdfJoint coordinate;
  coordinate.name = UniqueName(name, &joint_names_);
  coordinate.type = type;
  coordinate.axis = axis;
  coordinate.anchor = anchor;
  coordinate.lower = lower;
  coordinate.upper = upper;
  coordinate.line = line;
  // The first coordinate starts from the body's pose in its parent; the next from the frame
  // the previous one moved. Parent and child links are named in Finish.
  if (state.coordinates.empty()) coordinate.origin = state.pose;
  joint->coordinates.push_back(static_cast<int>(state.coordinates.size()));
  state.coordinates.push_back(std::move(coordinate));
}

absl::Status Reader::ReadJoint(const Node& node, int body, const std::string& childclass) {
  BodyState& state = states_[static_cast<std::size_t>(body)];
  MjcfJoint joint;
  joint.body = body;
  joint.line = node.line;
  Attributes a;
  if (node.name == "freejoint") {
    a = mjcf::Resolve(node, nullptr);
    joint.type = MjcfJointType::kFree;
  } else {
    absl::StatusOr<const DefaultClass*> defaults = ClassOf(node, childclass);
    if (!defaults.ok()) return defaults.status();
    a = mjcf::Resolve(node, (*defaults)->Kind("joint"));
    const std::string type = Text(a, "type", "hinge");
    if (type == "hinge") {
      joint.type = MjcfJointType::kHinge;
    } else if (type == "slide") {
      joint.type = MjcfJointType::kSlide;
    } else if (type == "ball") {
      joint.type = MjcfJointType::kBall;
    } else if (type == "free") {
      joint.type = MjcfJointType::kFree;
    } else {
      return AttributeError(a.at("type"), "type",
                            "not a MuJoCo joint type (hinge, slide, ball, free)");
    }
  }
  const std::string& body_name = model_.bodies[static_cast<std::size_t>(body)].name;
  const std::string name = Text(a, "name");
  if (!name.empty() && !written_joint_names_.insert(name).second) {
    return ErrorAt(node, absl::StrCat("joint name '", name, "' is used twice"));
  }
  joint.name = name.empty() ? absl::StrCat(body_name, "_joint", state.joints.size()) : name;
  if (joint.type == MjcfJointType::kFree) {
    if (model_.bodies[static_cast<std::size_t>(body)].parent != 0) {
      return ErrorAt(node, absl::StrCat("a free joint in body '", body_name,
                                        "', which is not a child of the world body (MuJoCo "
                                        "allows free joints only there)"));
    }
    const char* axes[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      AddCoordinate(body, absl::StrCat(joint.name, "/t", axes[k]), UrdfJointType::kPrismatic,
                    Vector3::Unit(k), Vector3::Zero(), 0.0, 0.0, node.line, &joint);
    }
    for (int k = 0; k < 3; ++k) {
      AddCoordinate(body, absl::StrCat(joint.name, "/r", axes[k]), UrdfJointType::kContinuous,
                    Vector3::Unit(k), Vector3::Zero(), 0.0, 0.0, node.line, &joint);
    }
    state.joints.push_back(std::move(joint));
    return absl::OkStatus();
  }
  absl::StatusOr<Vector3> pos = Vector(a, "pos", Vector3::Zero());
  if (!pos.ok()) return pos.status();
  if (joint.type == MjcfJointType::kBall) {
    const char* axes[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      AddCoordinate(body, absl::StrCat(joint.name, "/", axes[k]), UrdfJointType::kContinuous,
                    Vector3::Unit(k), *pos, 0.0, 0.0, node.line, &joint);
    }
    state.joints.push_back(std::move(joint));
    return absl::OkStatus();
  }
  absl::StatusOr<Vector3> axis = Vector(a, "axis", Vector3::UnitZ());
  if (!axis.ok()) return axis.status();
  if (const double norm = axis->norm(); !(std::isfinite(norm) && norm > 1e-15)) {
    return AttributeError(a.at("axis"), "axis", "the axis is zero (or too long to normalise)");
  }
  const bool hinge = joint.type == MjcfJointType::kHinge;
  const double unit = hinge && compiler_.angles.degrees ? M_PI / 180.0 : 1.0;
  absl::StatusOr<std::optional<std::vector<double>>> range = Numbers(a, "range", 2, 2);
  if (!range.ok()) return range.status();
  absl::StatusOr<std::optional<std::vector<double>>> ref = Numbers(a, "ref", 1, 1);
  if (!ref.ok()) return ref.status();
  joint.ref = *ref ? (**ref)[0] * unit : 0.0;
  bool limited = compiler_.autolimits && range->has_value();
  if (const std::string text = Text(a, "limited", "auto"); text == "true") {
    limited = true;
  } else if (text == "false") {
    limited = false;
  } else if (text != "auto") {
    return AttributeError(a.at("limited"), "limited", "expected true, false or auto");
  }
  double lower = 0.0, upper = 0.0;
  if (limited && *range) {
    lower = (**range)[0] * unit - joint.ref;
    upper = (**range)[1] * unit - joint.ref;
    if (!std::isfinite(lower) || !std::isfinite(upper)) {
      return AttributeError(a.at("range"), "range", "too large (less ref)");
    }
    if (lower > upper) {
      return AttributeError(a.at("range"), "range", "the lower limit is above the upper one");
    }
  }
  const UrdfJointType type = !hinge    ? UrdfJointType::kPrismatic
                             : limited ? UrdfJointType::kRevolute
                                       : UrdfJointType::kContinuous;
  AddCoordinate(body, joint.name, type, axis->normalized(), hinge ? *pos : Vector3::Zero(), lower,
                upper, node.line, &joint);
  state.joints.push_back(std::move(joint));
  return absl::OkStatus();
}

absl::Status Reader::ReadGeom(const Node& node, int body, const std::string& childclass) {
  absl::StatusOr<const DefaultClass*> defaults = ClassOf(node, childclass);
  if (!defaults.ok()) return defaults.status();
  absl::StatusOr<MjcfGeom> geom = mjcf::ReadGeom(
      node, mjcf::Resolve(node, (*defaults)->Kind("geom")), compiler_.angles, meshes_);
  if (!geom.ok()) return geom.status();
  geom->body = body;
  geom->class_name = (*defaults)->name;
  states_[static_cast<std::size_t>(body)].geoms.push_back(*std::move(geom));
  return absl::OkStatus();
}

bool Reader::Selected(const MjcfGeom& geom) const {
  const MjcfGeomSelection& selection = options_.solid;
  if (selection.classes.empty() && selection.groups.empty()) {
    return geom.contype != 0 || geom.conaffinity != 0;
  }
  if (std::count(selection.groups.begin(), selection.groups.end(), geom.group)) return true;
  for (int c = class_index_.at(geom.class_name); c >= 0;
       c = classes_[static_cast<std::size_t>(c)].parent) {
    const std::string& name = classes_[static_cast<std::size_t>(c)].name;
    if (std::count(selection.classes.begin(), selection.classes.end(), name)) return true;
  }
  return false;
}

// Links, joints and geoms in MuJoCo's order, the coordinates chained through links of their own.
void Reader::Finish() {
  UrdfRobot& robot = model_.robot;
  for (std::size_t b = 0; b < model_.bodies.size(); ++b) {
    MjcfBody& body = model_.bodies[b];
    BodyState& state = states_[b];
    const std::string parent_link =
        body.parent < 0 ? ""
                        : robot
                              .links[static_cast<std::size_t>(
                                  model_.bodies[static_cast<std::size_t>(body.parent)].link)]
                              .name;
    // The chain: coordinate k moves link k-1 (the parent's for k = 0) to link k, the last
    // being the body's own.
    std::string previous = parent_link;
    for (std::size_t k = 0; k + 1 < state.coordinates.size(); ++k) {
      UrdfLink virtual_link;
      virtual_link.name =
          UniqueName(absl::StrCat(body.name, "/", state.coordinates[k].name), &link_names_);
      virtual_link.line = body.line;
      state.coordinates[k].parent = previous;
      state.coordinates[k].child = virtual_link.name;
      previous = virtual_link.name;
      robot.links.push_back(std::move(virtual_link));
    }
    UrdfLink link;
    link.name = body.name;
    link.line = body.line;
    body.link = static_cast<int>(robot.links.size());
    if (b > 0 && state.coordinates.empty()) {
      UrdfJoint weld;
      weld.name = UniqueName(absl::StrCat(body.name, "_weld"), &joint_names_);
      weld.type = UrdfJointType::kFixed;
      weld.origin = state.pose;
      weld.line = body.line;
      state.coordinates.push_back(std::move(weld));
    }
    if (!state.coordinates.empty()) {
      state.coordinates.back().parent = previous;
      state.coordinates.back().child = link.name;
    }
    // The solid: the selected geoms, else the others with a warning; never planes.
    const auto solid = [](const MjcfGeom& g) {
      return g.element.geometry.shape != UrdfShape::kUnsupported;
    };
    bool any = false;
    for (MjcfGeom& g : state.geoms) {
      g.solid = solid(g) && Selected(g);
      any = any || g.solid;
    }
    if (!any) {
      for (MjcfGeom& g : state.geoms) g.solid = solid(g);
      link.from_visual = std::any_of(state.geoms.begin(), state.geoms.end(),
                                     [](const MjcfGeom& g) { return g.solid; });
      if (link.from_visual) {
        model_.warnings.push_back(absl::StrCat(
            "body '", body.name, "' (line ", body.line,
            ") has no collision geoms (contype and conaffinity 0, or none of the classes and "
            "groups asked for): its other geoms stand in for its solid"));
      }
    }
    for (MjcfGeom& g : state.geoms) {
      if (!solid(g)) {
        model_.warnings.push_back(
            absl::StrCat("geom ", g.name.empty() ? "" : absl::StrCat("'", g.name, "' "), "(line ",
                         g.element.line, ") of body '", body.name, "' is a ",
                         MjcfGeomTypeName(g.type), ", not a solid: left out"));
      }
      if (g.solid) link.elements.push_back(g.element);
      g.body = static_cast<int>(b);
      model_.geoms.push_back(std::move(g));
    }
    robot.links.push_back(std::move(link));
    const int first_coordinate = static_cast<int>(robot.joints.size());
    for (MjcfJoint& joint : state.joints) {
      for (int& c : joint.coordinates) c += first_coordinate;
      body.joints.push_back(static_cast<int>(model_.joints.size()));
      model_.joints.push_back(std::move(joint));
    }
    for (UrdfJoint& coordinate : state.coordinates) robot.joints.push_back(std::move(coordinate));
  }
}

absl::StatusOr<MjcfModel> Reader::Read() {
  const Node& root = document_.root;
  if (const std::string* name = root.Attribute("model"); name != nullptr) {
    model_.robot.name = *name;
  }
  for (const Node& child : root.children) {
    if (child.name != "compiler") continue;
    if (absl::Status s = ReadCompiler(child); !s.ok()) return s;
  }
  classes_.push_back(DefaultClass{"main", -1, {}});
  class_index_["main"] = 0;
  for (const Node& child : root.children) {
    if (child.name != "default") continue;
    if (absl::Status s = ReadDefault(child, -1); !s.ok()) return s;
  }
  for (const Node& child : root.children) {
    if (child.name != "asset") continue;
    for (const Node& asset : child.children) {
      if (asset.name != "mesh") continue;
      if (absl::Status s = ReadMesh(asset); !s.ok()) return s;
    }
  }
  link_names_.insert("world");
  for (const Node& child : root.children) {
    if (child.name == "worldbody") ReserveBodyNames(child, &link_names_);
  }
  MjcfBody world;
  world.name = "world";
  world.line = root.line;
  model_.bodies.push_back(world);
  states_.emplace_back();
  for (const Node& child : root.children) {
    if (child.name != "worldbody") continue;
    if (absl::Status s = ReadBodyChildren(child, 0, "main"); !s.ok()) return s;
  }
  // MuJoCo numbers bodies depth first, which is the order they were read in.
  Finish();
  return std::move(model_);
}

}  // namespace

const char* MjcfGeomTypeName(MjcfGeomType type) {
  switch (type) {
    case MjcfGeomType::kPlane:
      return "plane";
    case MjcfGeomType::kHfield:
      return "hfield";
    case MjcfGeomType::kSphere:
      return "sphere";
    case MjcfGeomType::kCapsule:
      return "capsule";
    case MjcfGeomType::kEllipsoid:
      return "ellipsoid";
    case MjcfGeomType::kCylinder:
      return "cylinder";
    case MjcfGeomType::kBox:
      return "box";
    case MjcfGeomType::kMesh:
      return "mesh";
  }
  return "unknown";
}

const char* MjcfJointTypeName(MjcfJointType type) {
  switch (type) {
    case MjcfJointType::kHinge:
      return "hinge";
    case MjcfJointType::kSlide:
      return "slide";
    case MjcfJointType::kBall:
      return "ball";
    case MjcfJointType::kFree:
      return "free";
  }
  return "unknown";
}

absl::StatusOr<MjcfModel> ParseMjcf(absl::string_view bytes, const std::string& model_path,
                                    const MjcfReadOptions& options) {
  absl::StatusOr<mjcf::Document> document = mjcf::ReadDocument(bytes, model_path);
  if (!document.ok()) return document.status();
  Reader reader(*document, options);
  return reader.Read();
}

absl::StatusOr<MjcfModel> ReadMjcf(const std::string& path, const MjcfReadOptions& options) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    return absl::NotFoundError(absl::StrCat(path, ": no such file"));
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) return absl::InvalidArgumentError(absl::StrCat(path, ": cannot be read"));
  return ParseMjcf(bytes.str(), path, options);
}

}  // namespace inscribe::robot
