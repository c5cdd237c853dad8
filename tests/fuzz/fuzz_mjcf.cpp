// libFuzzer target: the MJCF reader (ParseMjcf). The bytes are the model file of a folder the
// target makes once, holding an include file and a mesh folder. A refused document must say
// why, as INVALID_ARGUMENT starting "MJCF ". An accepted one must keep mjcf_robot.h's promises:
// the world body first; every body's link, every joint's coordinates and every geom's body
// exist; link and coordinate names unique and non-empty; finite origins with orthonormal
// rotations; positive, finite sizes; every mesh path inside the model's folder (nothing outside
// is ever named); a link's elements exactly its solid geoms; and the joints always a tree that
// Kinematics::Create takes, with rotations at sampled configurations. Any break aborts with
// the reason.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/mjcf_robot.h"

namespace {

namespace fs = std::filesystem;
using inscribe::Vector3;
using inscribe::robot::Kinematics;
using inscribe::robot::MjcfBody;
using inscribe::robot::MjcfGeom;
using inscribe::robot::MjcfJoint;
using inscribe::robot::MjcfModel;
using inscribe::robot::OriginRotation;
using inscribe::robot::UrdfElement;
using inscribe::robot::UrdfGeometry;
using inscribe::robot::UrdfJoint;
using inscribe::robot::UrdfLink;
using inscribe::robot::UrdfOrigin;
using inscribe::robot::UrdfShape;

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "fuzz_mjcf: %s\n", what.c_str());
  std::abort();
}

// The model's folder: inc.xml (defaults and a body, for <include file="inc.xml">) and meshes/.
const std::string& Folder() {
  static const std::string folder = [] {
    const fs::path path =
        fs::temp_directory_path() / absl::StrCat("inscribe_fuzz_mjcf_", ::getpid());
    fs::create_directories(path / "meshes");
    std::ofstream(path / "inc.xml") << R"(<mujoco>
  <default><default class="inc"><geom type="box" size="0.1 0.1 0.1"/></default></default>
  <worldbody><body name="included"><joint/><geom class="inc"/></body></worldbody>
</mujoco>
)";
    std::ofstream(path / "meshes" / "m.stl") << "solid m\nendsolid m\n";
    return fs::weakly_canonical(path).string();
  }();
  return folder;
}

bool Positive(double x) { return std::isfinite(x) && x > 0.0; }

void CheckOrigin(const UrdfOrigin& origin, const std::string& what) {
  if (!origin.xyz.allFinite()) Fail("a non-finite position: " + what);
  const Eigen::Matrix3d r = OriginRotation(origin);
  if (!r.allFinite() || !(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-9) ||
      std::abs(r.determinant() - 1.0) > 1e-9) {
    Fail("a rotation that is not one: " + what);
  }
}

void CheckShape(const UrdfGeometry& g, const std::string& what) {
  switch (g.shape) {
    case UrdfShape::kMesh:
      if (!absl::StartsWith(g.filename, Folder() + "/")) {
        Fail("a mesh path outside the model's folder: " + g.filename);
      }
      if (!g.scale.allFinite() || (g.scale.array() == 0.0).any()) Fail("a bad scale: " + what);
      break;
    case UrdfShape::kBox:
    case UrdfShape::kEllipsoid:
      if (!Positive(g.size.x()) || !Positive(g.size.y()) || !Positive(g.size.z())) {
        Fail("a size that is not positive and finite: " + what);
      }
      break;
    case UrdfShape::kCapsule:
    case UrdfShape::kCylinder:
      if (!Positive(g.radius) || !Positive(g.length)) Fail("a bad radius or length: " + what);
      break;
    case UrdfShape::kSphere:
      if (!Positive(g.radius)) Fail("a bad radius: " + what);
      break;
    case UrdfShape::kUnsupported:
      if (g.unsupported != "plane" && g.unsupported != "hfield") Fail("an unknown shape: " + what);
      break;
  }
}

void CheckModel(const MjcfModel& model) {
  const std::size_t links = model.robot.links.size();
  if (model.bodies.empty() || model.bodies[0].name != "world" || model.bodies[0].parent != -1) {
    Fail("the world body is not first");
  }
  std::set<std::string> names;
  for (const UrdfLink& link : model.robot.links) {
    if (link.name.empty() || !names.insert(link.name).second) Fail("link name: " + link.name);
  }
  names.clear();
  for (const UrdfJoint& joint : model.robot.joints) {
    if (joint.name.empty() || !names.insert(joint.name).second) Fail("joint name: " + joint.name);
    CheckOrigin(joint.origin, "joint " + joint.name);
    if (!joint.anchor.allFinite() || std::abs(joint.axis.norm() - 1.0) > 1e-12) {
      Fail("a bad anchor or axis: " + joint.name);
    }
    if (!std::isfinite(joint.lower) || !std::isfinite(joint.upper) || joint.lower > joint.upper) {
      Fail("limits not finite and ordered: " + joint.name);
    }
  }
  std::vector<int> solid(links, 0);
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const MjcfBody& body = model.bodies[b];
    if (body.link < 0 || static_cast<std::size_t>(body.link) >= links) Fail("a body's link");
    if (model.robot.links[static_cast<std::size_t>(body.link)].name != body.name) {
      Fail("a body's link is named otherwise: " + body.name);
    }
    if (b > 0 && (body.parent < 0 || static_cast<std::size_t>(body.parent) >= b)) {
      Fail("a body's parent does not come before it: " + body.name);
    }
  }
  for (const MjcfJoint& joint : model.joints) {
    const std::size_t expected = joint.type == inscribe::robot::MjcfJointType::kBall   ? 3
                                 : joint.type == inscribe::robot::MjcfJointType::kFree ? 6
                                                                                       : 1;
    if (joint.coordinates.size() != expected) Fail("coordinates of joint " + joint.name);
    for (int c : joint.coordinates) {
      if (c < 0 || static_cast<std::size_t>(c) >= model.robot.joints.size()) {
        Fail("a coordinate index of joint " + joint.name);
      }
    }
    if (!std::isfinite(joint.ref)) Fail("a non-finite ref: " + joint.name);
  }
  for (const MjcfGeom& geom : model.geoms) {
    if (geom.body < 0 || static_cast<std::size_t>(geom.body) >= model.bodies.size()) {
      Fail("a geom's body");
    }
    CheckOrigin(geom.element.origin, "geom at line " + std::to_string(geom.element.line));
    CheckShape(geom.element.geometry, "geom at line " + std::to_string(geom.element.line));
    if (geom.solid) {
      if (geom.element.geometry.shape == UrdfShape::kUnsupported) Fail("a plane as solid");
      ++solid[static_cast<std::size_t>(model.bodies[static_cast<std::size_t>(geom.body)].link)];
    }
  }
  for (std::size_t l = 0; l < links; ++l) {
    if (static_cast<int>(model.robot.links[l].elements.size()) != solid[l]) {
      Fail("a link's elements are not its solid geoms: " + model.robot.links[l].name);
    }
  }
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(model.robot);
  if (!kinematics.ok()) {
    Fail(absl::StrCat("an accepted model is not a tree: ", kinematics.status().message()));
  }
  for (const std::vector<double>& q : inscribe::robot::SampleConfigurations(*kinematics, 2, 1)) {
    absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses(q);
    if (!poses.ok()) Fail("LinkPoses refuses a sampled configuration");
    for (const Eigen::Isometry3d& pose : *poses) {
      // Huge but finite positions may overflow under composition: rotations only.
      if (!(pose.linear().transpose() * pose.linear())
               .isApprox(Eigen::Matrix3d::Identity(), 1e-6)) {
        Fail("a link pose's rotation is not a rotation");
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<MjcfModel> model = inscribe::robot::ParseMjcf(bytes, Folder() + "/model.xml");
  if (!model.ok()) {
    if (model.status().code() != absl::StatusCode::kInvalidArgument ||
        !absl::StartsWith(model.status().message(), "MJCF ")) {
      Fail(absl::StrCat("a refusal that is not INVALID_ARGUMENT \"MJCF ...\": ",
                        model.status().ToString()));
    }
    return 0;
  }
  CheckModel(*model);
  return 0;
}
