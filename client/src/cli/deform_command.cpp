#include "deform_command.h"

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "nlohmann/json.hpp"
#include "output_files.h"
#include "remote_options.h"
#include "service_session.h"
#include "sphere_output.h"

namespace inscribe::cli {
namespace {

struct DeformCliOptions {
  std::string reference_path;
  std::string spheres_path;
  std::string deformed_path;
  double xi = 0.0;
  bool strict = false;
  bool interpolated_normal = false;
  bool fill_holes = false;
  std::string output_path;
  std::string format;
  std::string link;  // cuRobo YAML link, read and written
  bool json = false;
  RemoteOptions remote;
};

// The reference's repair: the mildest levels only, which keep its vertices (the deformed file
// moves them by index): the safe fixes, or with --fill-holes also its holes closed. A crack
// weld renumbers vertices, so the reference is refused when it needed one (below).
RepairOptions DeformRepair(const DeformCliOptions& options) {
  RepairOptions repair;
  repair.level = options.fill_holes ? MeshRepair::kFill : MeshRepair::kSafe;
  return repair;
}

// The deformed file must be the reference file with its vertices moved: same vertex count,
// same triangles in the same order. Returns "" when it is, else what differs.
std::string DescribeTopologyDifference(const Mesh& reference, const Mesh& deformed) {
  if (deformed.num_vertices() != reference.num_vertices()) {
    return absl::StrFormat("it has %d vertices; the reference has %d", deformed.num_vertices(),
                           reference.num_vertices());
  }
  if (deformed.num_triangles() != reference.num_triangles()) {
    return absl::StrFormat("it has %d triangles; the reference has %d", deformed.num_triangles(),
                           reference.num_triangles());
  }
  for (Eigen::Index t = 0; t < reference.num_triangles(); ++t) {
    if (deformed.triangles.row(t) != reference.triangles.row(t)) {
      return absl::StrFormat("triangle %d is (%d, %d, %d); in the reference it is (%d, %d, %d)", t,
                             deformed.triangles(t, 0), deformed.triangles(t, 1),
                             deformed.triangles(t, 2), reference.triangles(t, 0),
                             reference.triangles(t, 1), reference.triangles(t, 2));
    }
  }
  return "";
}

// What deform checks here before calling the service: the three files read and checked
// against each other, the reference validated and hashed (to match the sphere file's hash),
// the deformed solid checked.
struct DeformInputs {
  SphereFile file;
  Mesh reference_file;  // as read: what is stored in the service (which validates it itself)
  std::string reference_sha256;
  Mesh deformed;  // the validated reference's triangles on the moved vertices
  std::string deformed_sha256;
  std::int64_t deformed_self_intersecting_pairs = 0;  // reported, not acted on
};

absl::StatusOr<DeformInputs> ReadInputs(const DeformCliOptions& options) {
  SphereFileReadOptions read;
  if (!options.format.empty()) read.format = *ParseSphereFileFormat(options.format);
  read.yaml_link = options.link;
  absl::StatusOr<SphereFile> file = ReadSphereFile(options.spheres_path, read);
  if (!file.ok()) return BadInputError(file.status().message());
  if (!file->set.has_contacts()) {
    return BadInputError(options.spheres_path +
                         ": no contact points; deform needs the JSON sphere file inscribe "
                         "generate writes (contacts are where each sphere touches the reference "
                         "mesh)");
  }
  absl::StatusOr<Mesh> reference = ReadMesh(options.reference_path);
  if (!reference.ok()) return BadInputError(reference.status().message());
  absl::StatusOr<Mesh> deformed_file = ReadMesh(options.deformed_path);
  if (!deformed_file.ok()) return BadInputError(deformed_file.status().message());
  if (const std::string why = DescribeTopologyDifference(*reference, *deformed_file);
      !why.empty()) {
    return BadInputError(options.deformed_path + " is not a deformation of " +
                         options.reference_path + ": " + why +
                         " (a deformed mesh keeps the reference's vertices and triangles, in "
                         "order, and only moves the vertices)");
  }
  DeformInputs in;
  in.reference_file = *reference;
  ValidateOptions validate;
  validate.repair = DeformRepair(options);
  absl::StatusOr<ValidatedMesh> solid = PrepareMesh(*std::move(reference), validate);
  if (!solid.ok()) {
    return UnusableMeshError(options.reference_path + ": " + std::string(solid.status().message()));
  }
  // The deformed file moves the reference's vertices as the file numbers them; once welded,
  // the solid's vertices are no longer those.
  if (solid->report.welded_vertices > 0 || solid->report.weld_collapsed_triangles > 0 ||
      solid->report.crack_vertices_welded > 0) {
    return BadInputError(
        absl::StrCat(options.reference_path, " repeats vertices at one position or has cracks (",
                     solid->report.welded_vertices + solid->report.crack_vertices_welded,
                     " vertices welded); deform needs a reference and deformed meshes whose "
                     "triangles share their "
                     "vertices: export them with vertices merged (welded)"));
  }
  in.reference_sha256 = FormatSha256(MeshSha256(solid->mesh));
  if (!file->mesh_sha256.empty() && file->mesh_sha256 != in.reference_sha256) {
    return BadInputError(options.spheres_path + " was made for mesh " + file->mesh_sha256 +
                         ", but " + options.reference_path + " is " + in.reference_sha256 +
                         (options.fill_holes ? ""
                                             : " (if the spheres were made with --fill-holes, "
                                               "pass it here too)"));
  }
  // The deformed solid is that of the reference, deformed.
  in.deformed = Mesh{deformed_file->vertices, solid->mesh.triangles};
  ValidateOptions check;
  check.fix_orientation = false;
  check.weld_vertices = false;  // the reference's triangles, on the file's vertices
  in.deformed_self_intersecting_pairs =
      ValidateMesh(in.deformed, check).report.self_intersecting_pairs;
  in.deformed_sha256 = FormatSha256(MeshSha256(in.deformed));
  in.file = *std::move(file);
  return in;
}

// The reference and the spheres are stored in the service, which keeps a deformer for them;
// the moved vertices go in one UpdateDeformation call.
absl::StatusOr<client::DeformationResult> Deform(const client::Client& client,
                                                 const DeformCliOptions& options,
                                                 const DeformInputs& in) {
  client::PutMeshOptions put;
  put.repair = DeformRepair(options);
  absl::StatusOr<client::PutMeshResult> mesh = client.PutMesh(in.reference_file, put);
  if (!mesh.ok()) return mesh.status();
  if (mesh->mesh_sha256 != in.reference_sha256) {
    return absl::InternalError(absl::StrCat("the service stored ", options.reference_path, " as ",
                                            mesh->mesh_sha256, ", not ", in.reference_sha256));
  }
  absl::StatusOr<client::PutSphereSetResult> set =
      client.PutSphereSet(in.file.set, mesh->mesh_sha256);
  if (!set.ok()) return set.status();
  client::DeformationSettings settings;
  settings.options.xi = options.xi;
  settings.options.strict = options.strict;
  settings.options.direction = options.interpolated_normal ? ContactDirection::kInterpolatedNormal
                                                           : ContactDirection::kCarriedFrame;
  settings.bounds = true;
  absl::StatusOr<client::DeformationResult> result = client.UpdateDeformation(
      mesh->mesh_sha256, set->sphere_set_key, in.deformed.vertices, settings);
  if (!result.ok()) {
    // Contacts that do not fit are the sphere file's fault, a degenerate deformed solid (the
    // vertex count was checked here) is the deformed mesh's.
    switch (result.status().code()) {
      case absl::StatusCode::kFailedPrecondition:
        return WithExitCode(WithContext(options.spheres_path, result.status()), kExitBadInput);
      case absl::StatusCode::kInvalidArgument:
        return WithExitCode(WithContext(options.deformed_path, result.status()), kExitUnusableMesh);
      default:
        return result.status();
    }
  }
  if (!result->bounds) return absl::InternalError("the service sent no error bounds");
  return *std::move(result);
}

void PrintText(const DeformCliOptions& options, const client::DeformationResult& result) {
  auto line = [](const char* key, const std::string& value) {
    std::cout << absl::StrFormat("%-26s %s\n", key, value);
  };
  const DeformationErrorBounds& bounds = *result.bounds;
  line("reference", options.reference_path);
  line("deformed", options.deformed_path);
  line("spheres", absl::StrFormat("%d (%d shrunk, %d dropped)", result.set.size(), result.shrunk,
                                  result.dropped));
  line("xi", absl::StrFormat("%.6g", result.xi));
  line("max protrusion", absl::StrFormat("%.6g", result.max_protrusion));
  line(bounds.exact ? "nerr (exact)" : "nerr bounds (Lemmas 1, 2)",
       bounds.exact ? absl::StrFormat("%.6f", bounds.nerr_lower)
                    : absl::StrFormat("%.6f .. %.6f", bounds.nerr_lower, bounds.nerr_upper));
  line("update", absl::StrFormat("%.4f s (%d closest-point queries)", result.seconds,
                                 result.closest_point_queries));
  line("bounds", absl::StrFormat("%.4f s", bounds.seconds));
}

void PrintSummary(const DeformCliOptions& options, const DeformInputs& in,
                  const client::DeformationResult& result, double load_seconds) {
  const DeformationErrorBounds& bounds = *result.bounds;
  nlohmann::json summary;
  summary["reference_mesh"] = options.reference_path;
  summary["reference_mesh_sha256"] = in.reference_sha256;
  summary["deformed_mesh"] = options.deformed_path;
  summary["mesh_sha256"] = in.deformed_sha256;
  summary["spheres"] = result.set.size();
  summary["reference_spheres"] = result.reference_spheres;
  summary["shrunk"] = result.shrunk;
  summary["dropped"] = result.dropped;
  summary["xi"] = result.xi;
  summary["strict"] = options.strict;
  summary["max_protrusion"] = result.max_protrusion;
  summary["max_shrink_steps"] = result.max_shrink_steps;
  summary["closest_point_queries"] = result.closest_point_queries;
  summary["seconds"] = result.seconds;
  summary["bounds_seconds"] = bounds.seconds;
  summary["load_seconds"] = load_seconds;
  summary["volume_mesh"] = bounds.volume_mesh;
  summary["volume_union"] = bounds.volume_union;
  summary["nerr_lower"] = bounds.nerr_lower;
  summary["nerr_upper"] = bounds.nerr_upper;
  // JSON has no infinity: null when Lemma 2's uniform-xi premise fails.
  summary["nerr_upper_uniform_xi"] = bounds.uniform_xi_holds
                                         ? nlohmann::json(bounds.nerr_upper_uniform_xi)
                                         : nlohmann::json(nullptr);
  summary["nerr_is_exact"] = bounds.exact;
  summary["self_intersecting_pairs"] = in.deformed_self_intersecting_pairs;
  if (options.remote.enabled()) summary["server"] = options.remote.server;
  if (!options.output_path.empty()) summary["output"] = options.output_path;
  std::cout << summary.dump() << "\n";
}

absl::Status RunDeform(const DeformCliOptions& options) {
  if (absl::Status output = CheckSphereOutputFormat(options.output_path, options.format);
      !output.ok()) {
    return output;
  }
  const auto load_start = std::chrono::steady_clock::now();
  absl::StatusOr<DeformInputs> in = ReadInputs(options);
  if (!in.ok()) return in.status();
  const double load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  absl::StatusOr<client::DeformationResult> result = Deform((*session)->client(), options, *in);
  if (!result.ok()) return result.status();
  const DeformationErrorBounds& bounds = *result->bounds;

  SphereFile out;
  out.set = result->set;
  out.mesh_sha256 = in->deformed_sha256;
  out.params = {
      {"reference_mesh_sha256", in->reference_sha256},
      {"xi", result->xi},
      {"strict", options.strict},
      {"direction",
       std::string(options.interpolated_normal ? "interpolated_normal" : "carried_frame")},
  };
  out.stats = {
      {"seconds", result->seconds},        {"bounds_seconds", bounds.seconds},
      {"volume_mesh", bounds.volume_mesh}, {"volume_union", bounds.volume_union},
      {"nerr_lower", bounds.nerr_lower},   {"nerr_upper", bounds.nerr_upper},
      {"nerr_is_exact", bounds.exact},     {"max_protrusion", result->max_protrusion},
      {"shrunk", result->shrunk},          {"dropped", result->dropped},
  };
  if (absl::Status written =
          EmitSphereFile(out, options.output_path, options.format, options.json, options.link);
      !written.ok()) {
    return written;
  }
  if (options.json) {
    PrintSummary(options, *in, *result, load_seconds);
  } else if (!options.output_path.empty()) {
    PrintText(options, *result);
  }
  return absl::OkStatus();
}

}  // namespace

void AddDeformCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<DeformCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "deform",
      "Move a generated sphere set onto a deformed version of its mesh (same triangles, moved "
      "vertices) and bound the new set's volumetric error; prints the sphere-set JSON unless "
      "-o or --json says otherwise");
  cmd->add_option("REFERENCE_MESH", options->reference_path,
                  "The mesh the spheres were generated for")
      ->required();
  cmd->add_option("SPHERES", options->spheres_path,
                  "Its sphere set, with contacts (the JSON inscribe generate writes)")
      ->required();
  cmd->add_option("DEFORMED_MESH", options->deformed_path,
                  "The reference mesh with its vertices moved")
      ->required();
  cmd->add_option("--xi", options->xi,
                  "No sphere sticks out this much or more, mesh units (default 0.25% of the "
                  "reference's largest bounding-box extent)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--strict", options->strict,
                "Internal and tangent output: radius = distance from the centre to the "
                "deformed boundary (nerr is then exact)");
  cmd->add_flag("--interpolated-normal", options->interpolated_normal,
                "Place centres along the interpolated vertex normal alone (the paper's formula "
                "as printed) instead of carrying each sphere's direction in its contact frame");
  cmd->add_flag("--fill-holes", options->fill_holes,
                "Close the reference's holes first, as generate --fill-holes did");
  cmd->add_option("-o,--output", options->output_path,
                  "Write the moved spheres here (format from --format or the extension)")
      ->check(WritableFile());
  cmd->add_option("--format", options->format, "Sphere file format (output; input by extension)")
      ->check(CLI::IsMember({"json", "sph", "csv", "obj", "yaml", "yml"}, CLI::ignore_case));
  cmd->add_option("--link", options->link,
                  "cuRobo YAML: the link to read the spheres of, and to write them under");
  cmd->add_flag("--json", options->json,
                "Print one JSON summary on stdout (spheres, seconds, nerr_lower, nerr_upper, "
                "max_protrusion, ...)");
  AddRemoteOptions(cmd, &options->remote, 60.0);
  SetExitStatusHelp(cmd, "a mesh cannot be used");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunDeform(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
