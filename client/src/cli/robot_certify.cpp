#include "robot_certify.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include "absl/strings/ascii.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "command_outcome.h"
#include "cover_verdict.h"
#include "inscribe/robot/link_cover.h"
#include "inscribe/robot/robot_file.h"
#include "inscribe/robot/robot_spheres.h"
#include "inscribe/robot/urdf_spherize.h"
#include "nlohmann/json.hpp"

namespace inscribe::cli {
namespace {

struct LinkRow {
  std::string link;
  int elements = 0;
  std::size_t spheres = 0;
  bool certified = false;
  double delta = 0.0;
  std::string note;                        // why not certified, or "no geometry"
  std::optional<CoverCertificate> failed;  // the first element's certificate that failed
};

// The link's elements as CombineElementCovers takes them: meshes certified by the service.
absl::StatusOr<std::vector<robot::ElementCover>> ElementCovers(
    const client::Client& client, const robot::UrdfLink& link, const std::vector<Sphere>& spheres,
    const robot::UrdfSpherizeOptions& spherize, const RobotCertifyOptions& options,
    std::string* problem) {
  std::vector<robot::ElementCover> covers;
  SphereSet set;
  set.spheres = spheres;
  for (const robot::UrdfElement& element : link.elements) {
    const std::string where = robot::DescribeUrdfElement(element, link.from_visual);
    robot::ElementCover cover;
    if (element.geometry.shape == robot::UrdfShape::kSphere) {
      cover.sphere = Sphere{element.origin.xyz, element.geometry.radius};
      covers.push_back(cover);
      continue;
    }
    absl::StatusOr<Mesh> mesh = robot::ElementMeshInLinkFrame(element, spherize);
    if (!mesh.ok()) {
      *problem = where + ": " + std::string(mesh.status().message());
      return covers;
    }
    client::PutMeshOptions put;
    put.repair = options.repair;
    absl::StatusOr<client::PutMeshResult> stored = client.PutMesh(*mesh, put);
    if (!stored.ok()) {
      if (stored.status().code() != absl::StatusCode::kFailedPrecondition) return stored.status();
      *problem = where + ": " + std::string(stored.status().message());
      return covers;
    }
    absl::StatusOr<CoverCertificate> certificate =
        client.CertifyCover(stored->mesh_sha256, set, options.certify);
    if (!certificate.ok()) return certificate.status();
    cover.certificate = *std::move(certificate);
    covers.push_back(std::move(cover));
  }
  return covers;
}

void PrintRows(const RobotCertifyOptions& options, robot::RobotSpheresFormat read_as,
               const std::vector<LinkRow>& rows) {
  bool all = true;
  double delta = 0.0;
  for (const LinkRow& row : rows) {
    all = all && (row.certified || row.elements == 0);
    if (row.certified) delta = std::max(delta, row.delta);
  }
  if (options.json) {
    nlohmann::json j;
    j["robot"] = options.robot_path;
    j["spheres_path"] = options.spheres_path;
    j["format"] = robot::RobotSpheresFormatName(read_as);
    j["certified"] = all;
    j["delta"] = delta;
    nlohmann::json links = nlohmann::json::array();
    for (const LinkRow& row : rows) {
      nlohmann::json link;
      link["link"] = row.link;
      link["elements"] = row.elements;
      link["spheres"] = row.spheres;
      link["certified"] = row.certified;
      if (row.certified) link["delta"] = row.delta;
      if (!row.note.empty()) link["note"] = row.note;
      if (row.failed && row.failed->uncovered_point) {
        const Vector3& p = *row.failed->uncovered_point;
        link["uncovered_point"] = {p.x(), p.y(), p.z()};
        link["uncovered_depth"] = row.failed->uncovered_depth;
        link["uncovered_gap"] = row.failed->uncovered_gap;
      }
      links.push_back(std::move(link));
    }
    j["links"] = std::move(links);
    if (!options.server.empty()) j["server"] = options.server;
    std::cout << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return;
  }
  std::size_t width = 4;
  for (const LinkRow& row : rows) width = std::max(width, row.link.size());
  const int w = static_cast<int>(width);
  std::cout << absl::StrFormat("%-*s  %8s  %7s  %-9s  %10s  %s\n", w, "link", "elements", "spheres",
                               "cover", "delta (mm)", "note");
  for (const LinkRow& row : rows) {
    const char* cover = row.elements == 0 ? "-" : row.certified ? "certified" : "NO";
    const std::string d = row.certified && row.elements > 0
                              ? absl::StrFormat("%.3f", row.delta * 1000.0)
                              : std::string("-");
    std::cout << absl::StrFormat("%-*s  %8d  %7d  %-9s  %10s  %s\n", w, row.link, row.elements,
                                 row.spheres, cover, d, row.note);
  }
  std::cout << absl::StrFormat(
      "%s (%s) on %s: %s", options.spheres_path, robot::RobotSpheresFormatName(read_as),
      options.robot_path, all ? "every link is a certified cover" : "NOT every link certified");
  if (all) std::cout << absl::StrFormat(", delta %.6g m at most", delta);
  std::cout << "\n";
}

}  // namespace

bool IsRobotDescriptionPath(const std::string& path) {
  const std::string extension =
      absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  return extension == ".urdf" || extension == ".xml" || extension == ".mjcf";
}

absl::Status RunRobotCertify(const client::Client& client, const RobotCertifyOptions& options) {
  absl::StatusOr<robot::RobotFile> file = robot::ReadRobotFile(options.robot_path);
  if (!file.ok()) return BadInputError(file.status().message());
  std::optional<robot::RobotSpheresFormat> format;
  if (!options.spheres_format.empty()) {
    absl::StatusOr<robot::RobotSpheresFormat> named =
        robot::ParseRobotSpheresFormat(options.spheres_format);
    if (!named.ok()) return UsageError(named.status().message());
    format = *named;
  }
  robot::RobotSpheresFormat read_as = robot::RobotSpheresFormat::kCurobo;
  absl::StatusOr<robot::RobotSpheres> model =
      robot::ReadRobotSpheresFile(options.spheres_path, format, &read_as);
  if (!model.ok()) return BadInputError(model.status().message());

  const robot::UrdfRobot& robot = file->robot();
  std::map<std::string, const LinkSpheres*> by_name;
  for (const LinkSpheres& link : model->links) by_name[link.link] = &link;
  std::set<std::string> robot_links;
  for (const robot::UrdfLink& link : robot.links) robot_links.insert(link.name);
  std::vector<std::string> unknown;
  for (const LinkSpheres& link : model->links) {
    if (robot_links.count(link.link) == 0) unknown.push_back(link.link);
  }
  if (!unknown.empty()) {
    return BadInputError(absl::StrFormat("%s names links %s has not: %s", options.spheres_path,
                                         options.robot_path, absl::StrJoin(unknown, ", ")));
  }
  robot::UrdfSpherizeOptions spherize;
  spherize.packages = robot::PackageSearchFromEnvironment(options.package_paths);
  spherize.urdf_dir = file->directory;

  std::vector<LinkRow> rows;
  int failed = 0;
  for (std::size_t l = 0; l < robot.links.size(); ++l) {
    if (!file->IsDescribedLink(static_cast<int>(l))) continue;
    const robot::UrdfLink& link = robot.links[l];
    const auto found = by_name.find(link.name);
    static const std::vector<Sphere> kNone;
    const std::vector<Sphere>& spheres = found == by_name.end() ? kNone : found->second->spheres;
    if (link.elements.empty() && spheres.empty()) continue;
    LinkRow row;
    row.link = link.name;
    row.elements = static_cast<int>(link.elements.size());
    row.spheres = spheres.size();
    if (link.elements.empty()) {
      row.certified = true;
      row.note = "no geometry to cover";
    } else if (spheres.empty()) {
      row.note = "no spheres for this link";
    } else {
      std::string problem;
      absl::StatusOr<std::vector<robot::ElementCover>> covers =
          ElementCovers(client, link, spheres, spherize, options, &problem);
      if (!covers.ok()) return covers.status();
      if (!problem.empty()) {
        row.note = problem;
      } else {
        absl::StatusOr<robot::LinkCoverVerdict> verdict =
            robot::CombineElementCovers(spheres, *covers);
        if (!verdict.ok()) return BugError(verdict.status().message());
        row.certified = verdict->certified;
        row.delta = verdict->delta;
        if (verdict->failed_element) {
          const robot::ElementCover& cover = (*covers)[*verdict->failed_element];
          const std::string where =
              robot::DescribeUrdfElement(link.elements[*verdict->failed_element], link.from_visual);
          if (cover.certificate) {
            row.failed = cover.certificate;
            row.note = where + ": " + CoverVerdict(*cover.certificate);
          } else {
            row.note = where + ": the <sphere> is in no single sphere of the set";
          }
        }
      }
    }
    failed += row.elements > 0 && !row.certified;
    rows.push_back(std::move(row));
  }
  PrintRows(options, read_as, rows);
  if (failed > 0) {
    return UnusableMeshError(absl::StrFormat(
        "%d of %d links with geometry are not certified covers", failed, rows.size()));
  }
  return absl::OkStatus();
}

}  // namespace inscribe::cli
