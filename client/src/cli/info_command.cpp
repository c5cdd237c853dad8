#include "info_command.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/view/report_json.h"
#include "output_files.h"
#include "remote_options.h"
#include "service_session.h"
#include "solid_loading.h"

namespace inscribe::cli {

using view::MeshReportJson;
namespace {

struct InfoOptions {
  std::string path;
  bool json = false;
  bool skip_self_intersections = false;
  SolidLoadOptions load;  // --scale and the repair options
  RemoteOptions remote;
  std::string output_path;  // -o: the repaired mesh
};

// What info prints: the service's report of the mesh, and how the file was read here.
struct InfoResult {
  MeshReport report;
  std::string sha256;  // "" when the mesh's indices or coordinates cannot be trusted
  ReadMeshInfo read;
  double seconds = 0.0;
};

void PrintText(const std::string& path, const InfoResult& result) {
  const MeshReport& report = result.report;
  const std::string& sha256 = result.sha256;
  const ReadMeshInfo& read = result.read;
  auto line = [](const char* key, const std::string& value) {
    std::cout << absl::StrFormat("%-20s %s\n", key, value);
  };
  line("mesh", path);
  line("sha256", sha256.empty() ? "-" : sha256);
  line("vertices",
       report.welded_vertices > 0
           ? absl::StrFormat("%d (%d welded: %d left)", report.vertices, report.welded_vertices,
                             report.vertices - report.welded_vertices)
           : std::to_string(report.vertices));
  std::string triangles = std::to_string(report.triangles);
  if (read.polygons_triangulated > 0) {
    triangles += absl::StrFormat(" (%d polygons triangulated)", read.polygons_triangulated);
  }
  if (report.hole_triangles_added > 0) {
    triangles += absl::StrFormat(" + %d filling %d %s", report.hole_triangles_added,
                                 report.holes_filled, report.holes_filled == 1 ? "hole" : "holes");
  }
  line("triangles", triangles);
  line("closed", report.closed() ? "yes" : "no");
  line("components", std::to_string(report.components));
  line("volume", absl::StrFormat("%.10g", report.volume));
  const BoundingBox& b = report.bbox;
  line("bbox min", absl::StrFormat("%.10g %.10g %.10g", b.min.x(), b.min.y(), b.min.z()));
  line("bbox max", absl::StrFormat("%.10g %.10g %.10g", b.max.x(), b.max.y(), b.max.z()));
  line("bbox diagonal", absl::StrFormat("%.10g", b.diagonal()));
  line("self-intersections",
       report.self_intersections_checked
           ? (report.self_intersecting_pairs == 0
                  ? std::string("none")
                  : absl::StrFormat("%d pairs", report.self_intersecting_pairs))
           : std::string("not checked"));
  line("checked in", absl::StrFormat("%.3f s", result.seconds));
  if (report.issues.empty()) {
    line("issues", "none");
  } else {
    std::cout << "issues\n";
    for (const MeshIssue& issue : report.issues) {
      std::cout << absl::StrFormat("  %-8s %s\n", SeverityName(issue.severity), issue.message);
    }
  }
  line("verdict", report.usable() ? "usable" : "NOT usable: " + report.first_error());
}

// -o: the mesh as validation returns it (welded, oriented, repaired as asked), validated here
// with the same options; it must hash as the service's report says (the same code on the same
// input), or nothing is written.
absl::Status WriteRepaired(const InfoOptions& options, Mesh mesh, const std::string& sha256) {
  ValidateOptions validate;
  validate.check_self_intersections = !options.skip_self_intersections;
  validate.repair = options.load.repair;
  const ValidatedMesh validated = ValidateMesh(std::move(mesh), validate);
  if (FormatSha256(MeshSha256(validated.mesh)) != sha256) {
    return absl::InternalError(absl::StrCat("the repaired mesh here hashes to ",
                                            FormatSha256(MeshSha256(validated.mesh)),
                                            ", the service's to ", sha256, "; nothing written"));
  }
  if (absl::Status written = WriteMesh(options.output_path, validated.mesh); !written.ok()) {
    return BadInputError(written.message());
  }
  ReportWritten(options.output_path,
                absl::StrCat(validated.mesh.num_triangles(), " triangles, as validated"));
  return absl::OkStatus();
}

absl::Status RunInfo(const InfoOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  InfoResult result;
  absl::StatusOr<Mesh> mesh = ReadScaledMesh(options.path, options.load.scale, &result.read);
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  client::InspectMeshOptions inspect;
  inspect.skip_self_intersections = options.skip_self_intersections;
  inspect.repair = options.load.repair;
  absl::StatusOr<client::InspectMeshResult> inspected =
      (*session)->client().InspectMesh(*mesh, inspect);
  if (!inspected.ok()) return inspected.status();
  result.report = std::move(inspected->report);
  result.sha256 = std::move(inspected->mesh_sha256);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const MeshReport& report = result.report;
  if (options.json) {
    nlohmann::json j = MeshReportJson(report, result.sha256);
    j["path"] = options.path;
    j["polygons_triangulated"] = result.read.polygons_triangulated;
    j["seconds"] = result.seconds;
    if (options.remote.enabled()) j["server"] = options.remote.server;
    std::cout << j.dump() << "\n";
  } else {
    PrintText(options.path, result);
  }
  if (!report.usable()) return UnusableMeshError(options.path + ": " + report.first_error());
  if (!options.output_path.empty()) return WriteRepaired(options, *std::move(mesh), result.sha256);
  return absl::OkStatus();
}

}  // namespace

void AddInfoCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info", "Validate a mesh and print its report, content hash, volume and bounding box");
  cmd->add_option("MESH", options->path, "Mesh file (.off, .obj, .stl, .ply, .dae, .gltf, .glb)")
      ->required();
  cmd->add_flag("--json", options->json, "Print one JSON object on stdout");
  cmd->add_flag("--skip-self-intersections", options->skip_self_intersections,
                "Skip the exact self-intersection test (faster on huge meshes)");
  AddSolidLoadOptions(cmd, &options->load);
  cmd->add_option("-o,--output", options->output_path,
                  "Write the mesh as validated and repaired (OFF, OBJ, PLY or STL by extension) "
                  "when it is usable")
      ->check(WritableFile());
  AddRemoteOptions(cmd, &options->remote, 60.0);
  SetExitStatusHelp(cmd,
                    "the mesh cannot be used (not a closed solid at the --repair level given)");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunInfo(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
