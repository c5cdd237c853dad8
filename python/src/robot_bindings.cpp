// Robots: spherize a URDF's links (what `inscribe urdf` does), and write the results.
#include <pybind11/stl.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/robot/urdf_spherize.h"
#include "inscribe/sphere_set_generation.h"
#include "interruptible.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

namespace fs = std::filesystem;
using robot::LinkSpherizeResult;
using robot::LinkStatus;

std::string ReadText(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) RaiseStatus(absl::NotFoundError(path + ": no such file"));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) RaiseStatus(absl::InvalidArgumentError(path + ": cannot be read"));
  return bytes.str();
}

// (N, 4) float64 [x, y, z, r] rows, a copy.
py::array_t<double> SphereArray(const std::vector<Sphere>& spheres) {
  py::array_t<double> result({static_cast<py::ssize_t>(spheres.size()), py::ssize_t{4}});
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    for (int k = 0; k < 3; ++k) result.mutable_at(i, k) = spheres[i].center[k];
    result.mutable_at(i, 3) = spheres[i].radius;
  }
  return result;
}

struct SpherizedRobot {
  std::string name;
  std::string urdf_path;
  std::vector<LinkSpherizeResult> links;
};

}  // namespace

void BindRobot(py::module_& m) {
  m.attr("DEFAULT_MAX_SPHERES_PER_LINK") = robot::kDefaultMaxSpheresPerLink;

  py::class_<LinkSpherizeResult>(m, "LinkSpheres", "One link of a spherized robot.")
      .def_readonly("link", &LinkSpherizeResult::link)
      .def_property_readonly(
          "status", [](const LinkSpherizeResult& r) { return robot::LinkStatusName(r.status); },
          "'spherized', 'skipped' or 'no_geometry'")
      .def_readonly("from_visual", &LinkSpherizeResult::from_visual)
      .def_readonly("elements", &LinkSpherizeResult::elements)
      .def_property_readonly(
          "spheres", [](const LinkSpherizeResult& r) { return SphereArray(r.spheres); },
          "(N, 4) float64 [x, y, z, r] in the link's frame, metres")
      .def_property_readonly(
          "kind", [](const LinkSpherizeResult& r) { return SphereSetKindName(r.kind); },
          "'cover', 'internal' or 'dilated'")
      .def_readonly("delta", &LinkSpherizeResult::delta,
                    "covers: the certified bound on how far the spheres reach past the link's "
                    "solid, padding included (metres); None otherwise")
      .def_property_readonly(
          "certified", [](const LinkSpherizeResult& r) { return r.delta.has_value(); },
          "whether the spheres are a certified cover of the link")
      .def_property_readonly(
          "cores", [](const LinkSpherizeResult& r) { return SphereArray(r.cores); },
          "(M, 4) float64 balls inside the link's solid (covers' cores; an internal set "
          "before padding), link frame, metres: the upper-bound side of certified distances")
      .def_readonly("budget", &LinkSpherizeResult::budget,
                    "spheres the link was given (budget modes), else 0")
      .def_readonly("error", &LinkSpherizeResult::error, "why a skipped link was skipped")
      .def_readonly("seconds", &LinkSpherizeResult::seconds)
      .def("__repr__", [](const LinkSpherizeResult& r) {
        return absl::StrCat("LinkSpheres('", r.link, "', ", robot::LinkStatusName(r.status), ", ",
                            r.spheres.size(), " spheres)");
      });

  py::class_<SpherizedRobot>(m, "SpherizedRobot", "A URDF robot with spheres for its links.")
      .def_readonly("name", &SpherizedRobot::name)
      .def_readonly("links", &SpherizedRobot::links)
      .def(
          "urdf",
          [](const SpherizedRobot& r) {
            return ValueOrRaise(robot::SpherizedUrdf(ReadText(r.urdf_path), r.links));
          },
          "The URDF text with one sphere <collision> per sphere in spherized links.")
      .def(
          "curobo_yaml",
          [](const SpherizedRobot& r) {
            std::vector<std::string> left_out;
            std::string yaml = robot::SpherizedCuroboYaml(r.links, r.name, &left_out);
            if (!left_out.empty()) {
              RaiseStatus(absl::InvalidArgumentError(
                  "links whose names cuRobo's YAML cannot carry: " + left_out.front()));
            }
            return yaml;
          },
          "cuRobo's collision_spheres YAML of the spherized links.");

  m.def(
      "spherize_urdf",
      [](const std::string& path, const std::string& kind, std::optional<std::int64_t> max_spheres,
         std::optional<std::int64_t> max_spheres_per_link, std::optional<double> max_protrusion,
         std::optional<double> voxel_size,
         const std::map<std::string, std::int64_t>& link_max_spheres, double padding,
         const std::vector<std::tuple<std::string, std::array<double, 3>, double>>& clip_planes,
         const std::vector<std::string>& package_paths, const py::object& progress) {
        const std::string bytes = ReadText(path);
        absl::StatusOr<robot::UrdfRobot> parsed = robot::ParseUrdf(bytes);
        if (!parsed.ok()) {
          RaiseStatus(absl::Status(parsed.status().code(),
                                   absl::StrCat(path, ": ", parsed.status().message())));
        }
        robot::UrdfSpherizeOptions options;
        options.kind = ValueOrRaise(ParseSphereSetKind(kind));
        options.max_spheres = max_spheres;
        options.max_spheres_per_link = max_spheres_per_link;
        options.max_protrusion = max_protrusion;
        options.voxel_size = voxel_size;
        options.link_max_spheres = link_max_spheres;
        options.padding = padding;
        for (const auto& [link, normal, offset] : clip_planes) {
          options.clip_planes.push_back(
              robot::ClipPlane{link, Vector3(normal[0], normal[1], normal[2]), offset});
        }
        options.packages = robot::PackageSearchFromEnvironment(package_paths);
        options.urdf_dir = fs::absolute(path).parent_path().string();
        absl::StatusOr<robot::RobotSpherizeResult> spherized;
        OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
          spherized = robot::SpherizeRobot(*parsed, options, control);
          return spherized.status();
        }));
        return SpherizedRobot{parsed->name, path, std::move(spherized->links)};
      },
      py::arg("path"), py::kw_only(), py::arg("kind") = "cover",
      py::arg("max_spheres") = py::none(), py::arg("max_spheres_per_link") = py::none(),
      py::arg("max_protrusion") = py::none(), py::arg("voxel_size") = py::none(),
      py::arg("link_max_spheres") = std::map<std::string, std::int64_t>{}, py::arg("padding") = 0.0,
      py::arg("clip_planes") =
          std::vector<std::tuple<std::string, std::array<double, 3>, double>>{},
      py::arg("package_paths") = std::vector<std::string>{}, py::arg("progress") = py::none(),
      "Spherizes every link of the URDF at `path` as `inscribe urdf` does: each link's "
      "collision geometry (visual when none) becomes spheres in the link's frame (metres): "
      "kind 'cover' (default; certified to hold the link, with delta), 'internal' or "
      "'dilated'. At most one mode: max_spheres for the whole robot (covers share it by "
      "greedy marginal gain on their estimated delta), max_spheres_per_link (the default, "
      "DEFAULT_MAX_SPHERES_PER_LINK), max_protrusion (covers: every link's delta at most this, "
      "fewest spheres) or voxel_size (internal, dilated). link_max_spheres: {link: N} budgets "
      "of their own. padding: metres added to every radius. clip_planes: [(link, (nx, ny, nz), "
      "offset)] cuts off what lies beyond n . x = offset in the link's frame. package_paths are "
      "searched for package:// before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH. A link that "
      "cannot be done is 'skipped' with its error, never silently dropped. Ctrl-C cancels. "
      "Returns a SpherizedRobot.");
}

}  // namespace inscribe::python
