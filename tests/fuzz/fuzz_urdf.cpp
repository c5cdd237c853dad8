// libFuzzer target: the URDF side of `inscribe urdf`. The bytes go through ParseUrdf; a refused
// document must say why. An accepted one must keep urdf_robot.h's promises (named, unique
// links; finite origins; positive sizes and radii; non-zero scales; a filename for every mesh)
// and its joints' (named, with parent and child; finite origins and limits, lower <= upper
// where used; unit axes; mimics naming a joint), Kinematics::Create must refuse it with a
// message or give finite rotations at sampled configurations, and the document must survive
// the writers: every link is given a made-up result (spherized with a few extreme
// but valid spheres, skipped with a reason full of XML-hostile text, or left alone, by the
// link's position), SpherizedUrdf must accept the document, and ParseUrdf must read its output
// back with the same links in the same order: a spherized link's elements are exactly its
// spheres (same doubles, zero rpy), any other link's elements are unchanged. The cuRobo YAML of
// the same results must parse back to the same spheres for every link it did not leave out.
// Any break aborts with the reason.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"

namespace {

using inscribe::Sphere;
using inscribe::Vector3;
using inscribe::robot::Kinematics;
using inscribe::robot::LinkSpherizeResult;
using inscribe::robot::LinkStatus;
using inscribe::robot::UrdfElement;
using inscribe::robot::UrdfGeometry;
using inscribe::robot::UrdfJoint;
using inscribe::robot::UrdfJointType;
using inscribe::robot::UrdfLink;
using inscribe::robot::UrdfRobot;
using inscribe::robot::UrdfShape;

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "fuzz_urdf: %s\n", what.c_str());
  std::abort();
}

bool Positive(double x) { return std::isfinite(x) && x > 0.0; }

void CheckPromises(const UrdfRobot& robot) {
  std::set<std::string> names;
  for (const UrdfLink& link : robot.links) {
    if (link.name.empty()) Fail("a parsed link has no name");
    if (!names.insert(link.name).second) Fail("two parsed links share the name " + link.name);
    for (const UrdfElement& element : link.elements) {
      if (!element.origin.xyz.allFinite() || !element.origin.rpy.allFinite()) {
        Fail("a parsed origin is not finite in link " + link.name);
      }
      const UrdfGeometry& g = element.geometry;
      switch (g.shape) {
        case UrdfShape::kMesh:
          if (g.filename.empty()) Fail("a parsed mesh has no filename");
          if (!g.scale.allFinite() || (g.scale.array() == 0.0).any()) {
            Fail("a parsed mesh scale is not finite and non-zero");
          }
          break;
        case UrdfShape::kBox:
          if (!Positive(g.size.x()) || !Positive(g.size.y()) || !Positive(g.size.z())) {
            Fail("a parsed box size is not positive");
          }
          break;
        case UrdfShape::kCylinder:
          if (!Positive(g.radius) || !Positive(g.length)) Fail("a parsed cylinder is not positive");
          break;
        case UrdfShape::kSphere:
          if (!Positive(g.radius)) Fail("a parsed sphere radius is not positive");
          break;
        case UrdfShape::kCapsule:
          if (!Positive(g.radius) || !Positive(g.length)) Fail("a parsed capsule is not positive");
          break;
        case UrdfShape::kEllipsoid:
          Fail("ParseUrdf made an MJCF-only shape (ellipsoid)");
        case UrdfShape::kUnsupported:
          break;
      }
    }
  }
  for (const UrdfJoint& joint : robot.joints) {
    if (joint.name.empty() || joint.parent.empty() || joint.child.empty()) {
      Fail("a parsed joint has no name, parent or child");
    }
    if (!joint.origin.xyz.allFinite() || !joint.origin.rpy.allFinite()) {
      Fail("a parsed joint origin is not finite: " + joint.name);
    }
    if (!joint.axis.allFinite() || std::abs(joint.axis.norm() - 1.0) > 1e-12) {
      Fail("a parsed joint axis is not a unit vector: " + joint.name);
    }
    const bool limited =
        joint.type == UrdfJointType::kRevolute || joint.type == UrdfJointType::kPrismatic;
    if (!std::isfinite(joint.lower) || !std::isfinite(joint.upper) ||
        (limited && joint.lower > joint.upper)) {
      Fail("parsed joint limits are not finite and ordered: " + joint.name);
    }
    if (joint.mimic && (joint.mimic->joint.empty() || !std::isfinite(joint.mimic->multiplier) ||
                        !std::isfinite(joint.mimic->offset))) {
      Fail("a parsed mimic has no joint or a non-finite number: " + joint.name);
    }
  }
}

// Kinematics::Create on any parsed robot: an error with a message, or a tree whose poses at a
// few sampled configurations are finite rigid motions.
void CheckKinematics(const UrdfRobot& robot) {
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  if (!kinematics.ok()) {
    if (kinematics.status().message().empty()) Fail("a refused tree has an empty error message");
    return;
  }
  if (kinematics->links() != static_cast<int>(robot.links.size())) {
    Fail("the kinematic tree has another link count");
  }
  for (const std::vector<double>& q : inscribe::robot::SampleConfigurations(*kinematics, 3, 1)) {
    absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses(q);
    if (!poses.ok()) Fail("LinkPoses refuses a sampled configuration");
    for (const Eigen::Isometry3d& pose : *poses) {
      // Huge but finite origins may overflow to inf under composition; NaN from inf - inf is
      // possible then too, so only the rotation part is checked.
      if (!pose.linear().allFinite() || !(pose.linear().transpose() * pose.linear())
                                             .isApprox(Eigen::Matrix3d::Identity(), 1e-6)) {
        Fail("a link pose's rotation is not a rotation");
      }
    }
  }
}

// A few valid spheres (finite centre, finite radius > 0) at the edges of the double range:
// what the writer must print so that the reader gets the same doubles back.
std::vector<Sphere> MadeUpSpheres(std::size_t link_index) {
  const double kMax = std::numeric_limits<double>::max();
  const double kDenormal = std::numeric_limits<double>::denorm_min();
  const double base = static_cast<double>(link_index);
  std::vector<Sphere> spheres;
  spheres.push_back({Vector3(0.1 * base, -1.0 / 3.0, 1e-300), 0.05 + base});
  spheres.push_back({Vector3(-kMax, kDenormal, -0.0), kDenormal});
  spheres.push_back({Vector3(1e22, -2.5e-8, 123456789.123456789), kMax});
  spheres.resize(1 + link_index % spheres.size());
  return spheres;
}

bool SameElement(const UrdfElement& a, const UrdfElement& b) {
  const UrdfGeometry& g = a.geometry;
  const UrdfGeometry& h = b.geometry;
  return a.name == b.name && a.origin.xyz == b.origin.xyz && a.origin.rpy == b.origin.rpy &&
         g.shape == h.shape && g.filename == h.filename && g.scale == h.scale && g.size == h.size &&
         g.radius == h.radius && g.length == h.length && g.unsupported == h.unsupported;
}

void CheckSpherizedLink(const UrdfLink& link, const LinkSpherizeResult& result) {
  if (link.from_visual || link.elements.size() != result.spheres.size()) {
    Fail(absl::StrCat("spherized link ", link.name, " reads back with ", link.elements.size(),
                      link.from_visual ? " visual" : " collision", " elements for ",
                      result.spheres.size(), " spheres"));
  }
  for (std::size_t i = 0; i < link.elements.size(); ++i) {
    const UrdfElement& element = link.elements[i];
    const Sphere& sphere = result.spheres[i];
    if (element.geometry.shape != UrdfShape::kSphere || element.geometry.radius != sphere.radius ||
        element.origin.xyz != sphere.center || element.origin.rpy != Vector3::Zero()) {
      Fail(absl::StrCat("spherized link ", link.name, " sphere ", i, " reads back differently"));
    }
  }
}

void CheckCuroboYaml(const std::vector<LinkSpherizeResult>& results, const UrdfRobot& robot) {
  std::vector<std::string> left_out;
  const std::string yaml = inscribe::robot::SpherizedCuroboYaml(results, robot.name, &left_out);
  const std::set<std::string> left(left_out.begin(), left_out.end());
  std::vector<const LinkSpherizeResult*> kept;
  for (const LinkSpherizeResult& result : results) {
    if (result.status == LinkStatus::kSpherized && left.count(result.link) == 0) {
      kept.push_back(&result);
    }
  }
  if (kept.empty()) return;  // a YAML without links is refused by its reader, by design
  absl::StatusOr<std::vector<inscribe::LinkSpheres>> parsed = inscribe::ParseCuroboYaml(yaml);
  if (!parsed.ok()) {
    Fail(absl::StrCat("the cuRobo YAML does not read back: ", parsed.status().message()));
  }
  if (parsed->size() != kept.size()) Fail("the cuRobo YAML reads back with another link count");
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const inscribe::LinkSpheres& link = (*parsed)[i];
    if (link.link != kept[i]->link || link.spheres.size() != kept[i]->spheres.size()) {
      Fail("the cuRobo YAML reads back with another link name or sphere count");
    }
    for (std::size_t j = 0; j < link.spheres.size(); ++j) {
      if (link.spheres[j].center != kept[i]->spheres[j].center ||
          link.spheres[j].radius != kept[i]->spheres[j].radius) {
        Fail("the cuRobo YAML reads back with other spheres in link " + link.link);
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<UrdfRobot> robot = inscribe::robot::ParseUrdf(bytes);
  if (!robot.ok()) {
    if (robot.status().message().empty()) Fail("a refused document has an empty error message");
    return 0;
  }
  CheckPromises(*robot);
  CheckKinematics(*robot);

  // Link i: spherized when i % 3 == 0, skipped when i % 3 == 1, left alone otherwise. The
  // reason text carries what comments and attributes must not break on.
  std::vector<LinkSpherizeResult> results;
  for (std::size_t i = 0; i < robot->links.size(); ++i) {
    const UrdfLink& link = robot->links[i];
    LinkSpherizeResult result;
    result.link = link.name;
    result.elements = static_cast<int>(link.elements.size());
    result.from_visual = link.from_visual;
    if (i % 3 == 0) {
      result.status = LinkStatus::kSpherized;
      result.spheres = MadeUpSpheres(i);
    } else if (i % 3 == 1) {
      result.status = LinkStatus::kSkipped;
      result.error = absl::StrCat("element at line 3 --> <!-- -- - '", link.name, "' ]]> &amp; -");
    } else {
      continue;
    }
    results.push_back(std::move(result));
  }

  absl::StatusOr<std::string> written = inscribe::robot::SpherizedUrdf(bytes, results);
  if (!written.ok()) {
    Fail(absl::StrCat("a document ParseUrdf accepted is refused by SpherizedUrdf: ",
                      written.status().message()));
  }
  absl::StatusOr<UrdfRobot> reread = inscribe::robot::ParseUrdf(*written);
  if (!reread.ok()) {
    Fail(absl::StrCat("the spherized URDF does not read back: ", reread.status().message()));
  }
  if (reread->name != robot->name || reread->links.size() != robot->links.size()) {
    Fail("the spherized URDF reads back with another robot name or link count");
  }
  for (std::size_t i = 0; i < robot->links.size(); ++i) {
    const UrdfLink& before = robot->links[i];
    const UrdfLink& after = reread->links[i];
    if (after.name != before.name) Fail("the spherized URDF reads back with links reordered");
    if (i % 3 == 0) {
      CheckSpherizedLink(after, results[i / 3 * 2]);
      continue;
    }
    bool same =
        after.from_visual == before.from_visual && after.elements.size() == before.elements.size();
    for (std::size_t j = 0; same && j < before.elements.size(); ++j) {
      same = SameElement(before.elements[j], after.elements[j]);
    }
    if (!same) Fail("link " + before.name + " was not spherized but reads back changed");
  }
  CheckCuroboYaml(results, *robot);
  return 0;
}
