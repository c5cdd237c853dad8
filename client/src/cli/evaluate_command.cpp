#include "evaluate_command.h"

#include <algorithm>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "cover_verdict.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/view/report_json.h"
#include "remote_options.h"
#include "robot_certify.h"
#include "service_session.h"
#include "solid_loading.h"

namespace inscribe::cli {

using view::QualityReportJson;
namespace {

struct EvaluateCliOptions {
  std::string mesh_path;
  std::string spheres_path;
  std::string format;
  int sph_level = -1;
  std::string link;
  QualityOptions quality;
  bool certify = false;
  CoverCertifyOptions certify_options;
  bool json = false;
  SolidLoadOptions load;                   // --scale and the repair options
  std::vector<std::string> package_paths;  // robots: where package:// URIs are looked for
  RemoteOptions remote;
};

// The mesh's key in the service and the service's report.
struct Evaluated {
  std::string mesh_sha256;
  QualityReport report;
};

void PrintText(const EvaluateCliOptions& options, const QualityReport& r) {
  auto line = [](const char* key, const std::string& value) {
    std::cout << absl::StrFormat("%-26s %s\n", key, value);
  };
  const double diagonal = r.bbox_diagonal > 0 ? r.bbox_diagonal : 1.0;
  line("mesh", options.mesh_path);
  line("spheres", absl::StrFormat("%s (%d)", options.spheres_path, r.spheres));
  line("volume mesh", absl::StrFormat("%.10g", r.volume_mesh));
  line("volume union (exact)", absl::StrFormat("%.10g", r.volume_union));
  line(r.nerr_is_exact ? "nerr (exact)" : "nerr (Lemma 1 lower bound)",
       absl::StrFormat("%.6f", r.nerr));
  line("protrusion max/mean/p95",
       absl::StrFormat("%.6g / %.6g / %.6g (%.3f%% of bbox diagonal at most)", r.protrusion_max,
                       r.protrusion_mean, r.protrusion_p95, 100.0 * r.protrusion_max / diagonal));
  line("protruding spheres", std::to_string(r.protruding_spheres));
  line("coverage", absl::StrFormat("%.4f of %d boundary samples within %.4g", r.coverage,
                                   r.surface_samples, r.coverage_tolerance));
  line("boundary to union",
       absl::StrFormat("mean %.6g, Hausdorff %.6g (%.3f%% of bbox diagonal; sampled)",
                       r.boundary_to_union_mean, r.boundary_to_union_hausdorff,
                       100.0 * r.boundary_to_union_hausdorff / diagonal));
  line("radius min/max", absl::StrFormat("%.6g / %.6g", r.radius_min, r.radius_max));
  if (r.voxel_size > 0) {
    line("(sigma, theta)-fat",
         absl::StrFormat("%s at sigma %.6g (fat up to %.6g)", r.fat ? "yes" : "no", r.voxel_size,
                         r.fat_up_to_voxel_size));
  } else {
    line("(sigma, theta)-fat up to", absl::StrFormat("sigma %.6g", r.fat_up_to_voxel_size));
  }
  line("evaluated in", absl::StrFormat("%.3f s", r.seconds));
}

// PutMesh, then Evaluate with the spheres sent inline.
absl::StatusOr<Evaluated> Evaluate(const client::Client& client, const EvaluateCliOptions& options,
                                   const SphereFile& file, const QualityOptions& quality) {
  absl::StatusOr<StoredSolid> solid = StoreSolid(client, options.mesh_path, options.load);
  if (!solid.ok()) return solid.status();
  absl::StatusOr<QualityReport> report = client.Evaluate(solid->sha256, file.set, quality);
  if (!report.ok()) return report.status();
  return Evaluated{solid->sha256, *std::move(report)};
}

void PrintCertificate(const EvaluateCliOptions& options, const SphereFile& file,
                      const std::string& mesh_sha256, const CoverCertificate& c) {
  if (options.json) {
    nlohmann::json j;
    j["mesh"] = options.mesh_path;
    j["mesh_sha256"] = mesh_sha256;
    j["spheres_path"] = options.spheres_path;
    j["spheres"] = file.set.size();
    j["certified"] = c.certified;
    j["certified_mesh_sha256"] = c.mesh_sha256;
    j["certified_spheres_sha256"] = c.spheres_sha256;
    j["delta"] = c.delta;
    j["resolution"] = c.resolution;
    j["cells"] = c.cells;
    j["cells_in_sphere"] = c.cells_in_sphere;
    j["cells_outside"] = c.cells_outside;
    j["failed_cells"] = c.failed_cells;
    if (c.uncovered_point) {
      const Vector3& p = *c.uncovered_point;
      j["uncovered_point"] = {p.x(), p.y(), p.z()};
      j["uncovered_depth"] = c.uncovered_depth;
      j["uncovered_gap"] = c.uncovered_gap;
    }
    j["seconds"] = c.seconds;
    if (options.remote.enabled()) j["server"] = options.remote.server;
    std::cout << j.dump() << "\n";
    return;
  }
  auto line = [](const char* key, const std::string& value) {
    std::cout << absl::StrFormat("%-26s %s\n", key, value);
  };
  line("mesh", options.mesh_path);
  line("spheres", absl::StrFormat("%s (%d)", options.spheres_path, file.set.size()));
  line("cover", CoverVerdict(c));
  line("proved for", absl::StrFormat("mesh %s, spheres %s", c.mesh_sha256, c.spheres_sha256));
  line("delta (reach outside)", absl::StrFormat("%.6g", c.delta));
  line("proof",
       absl::StrFormat("%d cells: %d in one sphere, %d outside the solid, %d failed; "
                       "finest side %.6g",
                       c.cells, c.cells_in_sphere, c.cells_outside, c.failed_cells, c.resolution));
  line("certified in", absl::StrFormat("%.3f s", c.seconds));
}

// --certify: PutMesh, then CertifyCover with the spheres sent inline. Not a cover is exit 1.
absl::Status RunCertify(const client::Client& client, const EvaluateCliOptions& options,
                        const SphereFile& file) {
  absl::StatusOr<StoredSolid> solid = StoreSolid(client, options.mesh_path, options.load);
  if (!solid.ok()) return solid.status();
  absl::StatusOr<CoverCertificate> certificate =
      client.CertifyCover(solid->sha256, file.set, options.certify_options);
  if (!certificate.ok()) return certificate.status();
  PrintCertificate(options, file, solid->sha256, *certificate);
  if (!certificate->certified) {
    return CommandError(absl::StatusCode::kFailedPrecondition,
                        options.spheres_path + " is not a certified cover of " + options.mesh_path,
                        kExitUnusableMesh);
  }
  return absl::OkStatus();
}

// `evaluate --certify ROBOT SPHERES`: the robot's links, each against its spheres.
absl::Status RunRobotEvaluate(const EvaluateCliOptions& options) {
  if (!options.certify) {
    return UsageError(options.mesh_path +
                      " is a robot: robot sphere files are checked link by link with --certify");
  }
  if (options.load.scale != 1.0 || !options.link.empty() || options.sph_level != -1) {
    return UsageError("--scale, --link and --sph-level are for one mesh, not a robot");
  }
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  RobotCertifyOptions robot;
  robot.robot_path = options.mesh_path;
  robot.spheres_path = options.spheres_path;
  robot.spheres_format = options.format;
  robot.package_paths = options.package_paths;
  robot.certify = options.certify_options;
  robot.repair = options.load.repair;
  robot.json = options.json;
  if (options.remote.enabled()) robot.server = options.remote.server;
  return RunRobotCertify((*session)->client(), robot);
}

absl::Status RunEvaluate(const EvaluateCliOptions& options) {
  if (IsRobotDescriptionPath(options.mesh_path)) return RunRobotEvaluate(options);
  SphereFileReadOptions read;
  if (!options.format.empty()) {
    absl::StatusOr<SphereFileFormat> format = ParseSphereFileFormat(options.format);
    if (!format.ok()) {
      return UsageError(std::string(format.status().message()) +
                        "; robot sphere formats go with a robot (.urdf, .xml) and --certify");
    }
    read.format = *format;
  }
  read.sph_level = options.sph_level;
  read.yaml_link = options.link;
  absl::StatusOr<SphereFile> file = ReadSphereFile(options.spheres_path, read);
  if (!file.ok()) return BadInputError(file.status().message());
  QualityOptions quality = options.quality;
  if (quality.voxel_size == 0.0) {
    for (const auto& [key, value] : file->params) {
      if (key == "voxel_size" && std::holds_alternative<double>(value)) {
        quality.voxel_size = std::get<double>(value);
      }
    }
  }
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  if (options.certify) return RunCertify((*session)->client(), options, *file);
  const absl::StatusOr<Evaluated> evaluated =
      Evaluate((*session)->client(), options, *file, quality);
  if (!evaluated.ok()) return evaluated.status();
  if (!file->mesh_sha256.empty() && file->mesh_sha256 != evaluated->mesh_sha256) {
    std::cerr << "inscribe: warning: " << options.spheres_path << " was made for mesh "
              << file->mesh_sha256 << ", not " << evaluated->mesh_sha256 << "\n";
  }
  if (options.json) {
    nlohmann::json j = QualityReportJson(evaluated->report);
    j["mesh"] = options.mesh_path;
    j["mesh_sha256"] = evaluated->mesh_sha256;
    j["spheres_path"] = options.spheres_path;
    if (options.remote.enabled()) j["server"] = options.remote.server;
    std::cout << j.dump() << "\n";
  } else {
    PrintText(options, evaluated->report);
  }
  return absl::OkStatus();
}

}  // namespace

void AddEvaluateCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<EvaluateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Quality of any sphere set against a mesh: exact nerr (or its lower bound for spheres "
      "that stick out), protrusion, coverage, boundary-to-union distance, fatness");
  cmd->add_option("MESH", options->mesh_path,
                  "Mesh file (.off, .obj, .stl, .ply), or with --certify a robot (.urdf, MJCF "
                  ".xml) whose links are checked one by one")
      ->required();
  cmd->add_option("SPHERES", options->spheres_path,
                  "Sphere file (.json, .sph, .csv, cuRobo .yml/.yaml); for a robot its sphere "
                  "file in any planner format (.yml cuRobo, .xrdf, .srdf, .urdf VAMP or MorphIt)")
      ->required();
  cmd->add_option("--format", options->format,
                  "Sphere file format (default: from extension; for a robot, also the content)")
      ->check(CLI::IsMember({"json", "sph", "csv", "yaml", "yml", "curobo", "xrdf", "srdf", "urdf",
                             "vamp", "morphit"},
                            CLI::ignore_case));
  cmd->add_option("--package-path", options->package_paths,
                  "Robots: a directory holding ROS packages for package:// URIs; repeatable");
  cmd->add_option("--link", options->link,
                  "cuRobo YAML with several links: the link whose spheres to evaluate");
  cmd->add_option("--sph-level", options->sph_level,
                  ".sph tree level to evaluate (-1 = the leaves)")
      ->capture_default_str();
  cmd->add_option("--quality-samples,--samples", options->quality.surface_samples,
                  "Boundary samples for coverage and Hausdorff distance (as generate's)")
      ->capture_default_str();
  cmd->add_option("--coverage-tolerance", options->quality.coverage_tolerance,
                  "Covered = within this of the union, mesh units (default 1e-3 of the "
                  "bounding-box diagonal)");
  cmd->add_option("--voxel-size", options->quality.voxel_size,
                  "Voxel size for the fatness test (default: the file's, if it has one)");
  AddSolidLoadOptions(cmd, &options->load);
  cmd->add_flag("--certify", options->certify,
                "Instead of the quality report: prove that the spheres contain the whole solid "
                "(a cover), or give a point of the solid in no sphere; with delta, a sound bound "
                "on how far they reach outside it. Exit 1 when not certified");
  cmd->add_option("--cover-resolution,--certify-resolution", options->certify_options.resolution,
                  "With --certify: the proof's finest cell side, as a fraction of the largest "
                  "bounding-box side")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "Print one JSON object on stdout");
  AddRemoteOptions(cmd, &options->remote, 60.0);
  SetExitStatusHelp(
      cmd, "the mesh cannot be used, or with --certify the spheres are not a certified cover");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunEvaluate(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
