#include "mjcf_geoms.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/mjcf_orientation.h"

namespace inscribe::robot::mjcf {

absl::StatusOr<MjcfGeom> ReadGeom(const Node& node, const Attributes& a,
                                  const AngleSettings& angles,
                                  const std::map<std::string, MeshAsset>& meshes) {
  MjcfGeom geom;
  geom.name = Text(a, "name");
  geom.element.name = geom.name;
  geom.element.line = node.line;
  static const std::pair<const char*, MjcfGeomType> kTypes[] = {
      {"plane", MjcfGeomType::kPlane},
      {"hfield", MjcfGeomType::kHfield},
      {"sphere", MjcfGeomType::kSphere},
      {"capsule", MjcfGeomType::kCapsule},
      {"ellipsoid", MjcfGeomType::kEllipsoid},
      {"cylinder", MjcfGeomType::kCylinder},
      {"box", MjcfGeomType::kBox},
      {"mesh", MjcfGeomType::kMesh}};
  const std::string type = Text(a, "type", "sphere");
  const auto found = std::find_if(std::begin(kTypes), std::end(kTypes),
                                  [&](const auto& t) { return type == t.first; });
  if (found == std::end(kTypes)) {
    return AttributeError(a.at("type"), "type",
                          "not a MuJoCo geom type (plane, hfield, sphere, capsule, ellipsoid, "
                          "cylinder, box, mesh)");
  }
  geom.type = found->second;
  for (auto [field, name, fallback] :
       {std::tuple{&geom.group, "group", 0}, std::tuple{&geom.contype, "contype", 1},
        std::tuple{&geom.conaffinity, "conaffinity", 1}}) {
    absl::StatusOr<int> value = Integer(a, name, fallback);
    if (!value.ok()) return value.status();
    *field = *value;
  }
  absl::StatusOr<std::optional<std::vector<double>>> size = Numbers(a, "size", 1, 3);
  if (!size.ok()) return size.status();
  std::vector<double> s = size->value_or(std::vector<double>{});
  s.resize(3, 0.0);
  absl::StatusOr<std::optional<std::vector<double>>> fromto = Numbers(a, "fromto", 6, 6);
  if (!fromto.ok()) return fromto.status();
  UrdfOrigin& origin = geom.element.origin;
  if (*fromto) {
    const bool elongated = geom.type == MjcfGeomType::kCapsule ||
                           geom.type == MjcfGeomType::kCylinder ||
                           geom.type == MjcfGeomType::kBox || geom.type == MjcfGeomType::kEllipsoid;
    if (!elongated) {
      return AttributeError(a.at("fromto"), "fromto",
                            absl::StrCat("fromto is for capsules, cylinders, boxes and "
                                         "ellipsoids, not a ",
                                         type));
    }
    if (node.Attribute("pos") != nullptr) {
      return ErrorAt(node, "<geom> has both pos and fromto; give one");
    }
    const std::vector<double>& f = **fromto;
    const Vector3 from(f[0], f[1], f[2]), to(f[3], f[4], f[5]);
    absl::StatusOr<Eigen::Matrix3d> rotation = MjcfZAxisRotation(from - to);
    if (!rotation.ok() || (from - to).norm() < 1e-10) {
      return AttributeError(a.at("fromto"), "fromto", "its two points coincide");
    }
    origin.xyz = from + 0.5 * (to - from);  // no overflow where from + to would
    origin.rotation = *rotation;
    // The half length along the axis; boxes and ellipsoids take size[0] across it both ways.
    const double half = 0.5 * (from - to).norm();
    if (geom.type == MjcfGeomType::kCapsule || geom.type == MjcfGeomType::kCylinder) {
      s = {s[0], half, 0.0};
    } else {
      s = {s[0], s[0], half};
    }
  } else {
    absl::StatusOr<Vector3> pos = Vector(a, "pos", Vector3::Zero());
    if (!pos.ok()) return pos.status();
    absl::StatusOr<Eigen::Matrix3d> rotation = Orientation(a, node, angles);
    if (!rotation.ok()) return rotation.status();
    origin.xyz = *pos;
    origin.rotation = *rotation;
  }
  const auto need_positive = [&](int count) -> absl::Status {
    for (int k = 0; k < count; ++k) {
      if (!(s[static_cast<std::size_t>(k)] > 0.0)) {
        return ErrorAt(node,
                       absl::StrCat("<geom type=\"", type, "\"> needs ", count, " positive size",
                                    count == 1 ? "" : "s", " (size=\"", Text(a, "size"), "\")"));
      }
    }
    return absl::OkStatus();
  };
  UrdfGeometry& shape = geom.element.geometry;
  absl::Status sized;
  switch (geom.type) {
    case MjcfGeomType::kPlane:
    case MjcfGeomType::kHfield:
      shape.unsupported = type;
      break;
    case MjcfGeomType::kSphere:
      sized = need_positive(1);
      shape.shape = UrdfShape::kSphere;
      shape.radius = s[0];
      break;
    case MjcfGeomType::kCapsule:
    case MjcfGeomType::kCylinder:
      sized = need_positive(2);
      shape.shape =
          geom.type == MjcfGeomType::kCapsule ? UrdfShape::kCapsule : UrdfShape::kCylinder;
      shape.radius = s[0];
      shape.length = 2.0 * s[1];
      break;
    case MjcfGeomType::kBox:
    case MjcfGeomType::kEllipsoid:
      sized = need_positive(3);
      shape.shape = geom.type == MjcfGeomType::kBox ? UrdfShape::kBox : UrdfShape::kEllipsoid;
      // URDF's boxes take side lengths, ellipsoids semi-axes; MJCF gives half sizes.
      shape.size = Vector3(s[0], s[1], s[2]) * (geom.type == MjcfGeomType::kBox ? 2.0 : 1.0);
      break;
    case MjcfGeomType::kMesh: {
      const std::string mesh = Text(a, "mesh");
      const auto asset = meshes.find(mesh);
      if (mesh.empty() || asset == meshes.end()) {
        return ErrorAt(
            node, mesh.empty()
                      ? std::string("<geom type=\"mesh\"> has no mesh attribute")
                      : absl::StrCat("<geom mesh=\"", mesh, "\">: no <mesh> asset has that name"));
      }
      shape.shape = UrdfShape::kMesh;
      shape.filename = asset->second.path;
      shape.scale = asset->second.scale;
      break;
    }
  }
  if (!sized.ok()) return sized;
  if (!std::isfinite(shape.length) || !shape.size.allFinite()) {
    return ErrorAt(node, absl::StrCat("<geom size=\"", Text(a, "size"), "\">: too large"));
  }
  if (geom.type != MjcfGeomType::kMesh && a.count("mesh")) {
    return ErrorAt(node, absl::StrCat("<geom type=\"", type,
                                      "\" mesh=...>: a primitive fitted to a mesh is not read; "
                                      "give the primitive's size, or type=\"mesh\""));
  }
  return geom;
}

}  // namespace inscribe::robot::mjcf
