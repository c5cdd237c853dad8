// Robots: spherize a URDF's links (what `inscribe urdf` does), and write the results.
#include <pybind11/stl.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/robot/urdf_spherize.h"
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
          "spheres",
          [](const LinkSpherizeResult& r) {
            py::array_t<double> result(
                {static_cast<py::ssize_t>(r.spheres.size()), py::ssize_t{4}});
            for (std::size_t i = 0; i < r.spheres.size(); ++i) {
              for (int k = 0; k < 3; ++k) result.mutable_at(i, k) = r.spheres[i].center[k];
              result.mutable_at(i, 3) = r.spheres[i].radius;
            }
            return result;
          },
          "(N, 4) float64 [x, y, z, r] in the link's frame, metres")
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
      [](const std::string& path, std::optional<std::int64_t> max_spheres_per_link,
         std::optional<double> voxel_size, const std::vector<std::string>& package_paths) {
        if (max_spheres_per_link && voxel_size) {
          throw py::value_error("give max_spheres_per_link or voxel_size, not both");
        }
        const std::string bytes = ReadText(path);
        absl::StatusOr<robot::UrdfRobot> parsed = robot::ParseUrdf(bytes);
        if (!parsed.ok()) {
          RaiseStatus(absl::Status(parsed.status().code(),
                                   absl::StrCat(path, ": ", parsed.status().message())));
        }
        robot::UrdfSpherizeOptions options;
        options.voxel_size = voxel_size.value_or(0.0);
        options.max_spheres_per_link =
            voxel_size ? 0 : max_spheres_per_link.value_or(robot::kDefaultMaxSpheresPerLink);
        if (options.voxel_size == 0.0 && options.max_spheres_per_link <= 0) {
          throw py::value_error("max_spheres_per_link must be at least 1");
        }
        options.packages = robot::PackageSearchFromEnvironment(package_paths);
        options.urdf_dir = fs::absolute(path).parent_path().string();
        SpherizedRobot result{parsed->name, path, {}};
        {
          py::gil_scoped_release release;
          for (const robot::UrdfLink& link : parsed->links) {
            result.links.push_back(robot::SpherizeLink(link, options));
          }
        }
        return result;
      },
      py::arg("path"), py::kw_only(), py::arg("max_spheres_per_link") = py::none(),
      py::arg("voxel_size") = py::none(), py::arg("package_paths") = std::vector<std::string>{},
      "Spherizes every link of the URDF at `path` as `inscribe urdf` does: each link's "
      "collision geometry (visual when none) becomes internal spheres in the link's frame "
      "(metres). At most max_spheres_per_link per link (default DEFAULT_MAX_SPHERES_PER_LINK) "
      "or a voxel_size in metres. package_paths are searched for package:// before "
      "ROS_PACKAGE_PATH and AMENT_PREFIX_PATH. A link that cannot be done is 'skipped' with "
      "its error, never silently dropped. Returns a SpherizedRobot.");
}

}  // namespace inscribe::python
