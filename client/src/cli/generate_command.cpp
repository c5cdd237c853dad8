#include "generate_command.h"

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/view/report_json.h"
#include "output_files.h"
#include "progress_bar.h"
#include "remote_options.h"
#include "service_session.h"
#include "solid_loading.h"
#include "sphere_output.h"

namespace inscribe::cli {

using view::QualityReportJson;
namespace {

struct GenerateCliOptions {
  std::string mesh_path;
  SphereSetParameters parameters;  // every default is core's
  std::string output_path;
  std::string format;
  std::string link;  // cuRobo YAML link name
  bool json = false;
  SolidLoadOptions load;  // --scale and the repair options
  RemoteOptions remote;
};

// What generate reports: the service's figures, in either mode.
struct Generated {
  GeneratedSphereSet result;  // S_D, S_D+ with --dilate, or a cover with --cover
  std::string mesh_sha256;
  std::int64_t triangles = 0;  // of the validated mesh
  // The service's validation report: what it repaired of the surface; the set and its
  // certificate are then about the repaired mesh, mesh_sha256, only.
  MeshReport mesh_report;
  double load_seconds = 0.0;  // reading, storing and validation
  // This call's Generate, wall clock: on a cache hit far less than result.generation_seconds,
  // the original computation's.
  double call_seconds = 0.0;
  // Remote mode only: the server's key of the set and where it came from ("computed",
  // "memory", "disk", "joined").
  std::string sphere_set_key, cache;
};

// PutMesh, then Generate with the progress bar fed by the service's messages.
absl::StatusOr<Generated> Generate(const client::Client& client,
                                   const GenerateCliOptions& options) {
  absl::StatusOr<StoredSolid> solid = StoreSolid(client, options.mesh_path, options.load);
  if (!solid.ok()) return solid.status();

  client::GenerateSettings settings;
  settings.parameters = options.parameters;
  settings.repair = options.load.repair;
  ProgressBar progress("generating");
  client::GenerateOptions call;
  call.on_progress = [&progress](double fraction) { progress.Update(fraction); };
  // The client uploads the mesh again if the service evicted it after StoreSolid.
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<client::GenerateResult> result =
      client.Generate(solid->sha256, solid->mesh, settings, call);
  const double call_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!result.ok()) {
    // Parameters the service refuses are a bad command line.
    if (result.status().code() == absl::StatusCode::kInvalidArgument) {
      return WithExitCode(result.status(), kExitUsage);
    }
    return result.status();
  }
  if (options.parameters.evaluate && !result->quality) {
    return absl::InternalError("the service sent no quality report");
  }
  Generated g;
  g.mesh_sha256 = std::move(result->mesh_sha256);
  g.sphere_set_key = std::move(result->sphere_set_key);
  g.cache = std::move(result->cache);
  g.result = *std::move(result);  // the GeneratedSphereSet part
  g.triangles = solid->report.triangles;
  g.mesh_report = solid->report;
  g.load_seconds = solid->seconds;
  g.call_seconds = call_seconds;
  return g;
}

void PrintSummary(const GenerateCliOptions& options, const Generated& g) {
  const SphereSetParameters& p = options.parameters;
  const GeneratedSphereSet& r = g.result;
  nlohmann::json summary = QualityReportJson(*r.quality);
  summary["mesh"] = options.mesh_path;
  summary["mesh_sha256"] = g.mesh_sha256;
  summary["triangles"] = g.triangles;
  if (g.mesh_report.geometry_repaired()) summary["mesh_repairs"] = g.mesh_report.repairs();
  if (g.mesh_report.wrapped) summary["mesh_wrap_reach"] = g.mesh_report.wrap_reach;
  summary["voxel_size"] = r.voxel_size;
  summary["object_angle"] = p.medial.object_angle;
  summary["samples"] = p.medial.samples;
  summary["subdivide_boundary"] = p.medial.subdivide_boundary;
  if (const std::optional<std::int64_t> budget = EffectiveMaxSpheres(p)) {
    summary["max_spheres"] = *budget;
  }
  if (p.max_protrusion) summary["max_protrusion"] = *p.max_protrusion;
  summary["seconds"] = g.call_seconds;
  summary["generation_seconds"] = r.generation_seconds;
  summary["load_seconds"] = g.load_seconds;
  if (r.kind != SphereSetKind::kCover) {  // figures of the medial run (as GenerationSphereFile)
    summary["epsilon"] = r.epsilon;
    summary["search_runs"] = r.runs;
    summary["selection"] = SphereSelectionName(r.selection);
    if (r.selection == SphereSelection::kOptimised) {
      summary["pool_size"] = r.pool_size;
      summary["covered_fraction"] = r.covered_fraction;
    }
    summary["visited_voxels"] = r.stats.visited_voxels;
    summary["screened_voxels"] = r.stats.screened_voxels;
    summary["closest_point_queries"] = r.stats.closest_point_queries;
  }
  summary[kKindParam] = SphereSetKindName(r.kind);
  NamedValues figures = r.dilation ? DilationFigures(*r.dilation) : NamedValues();
  if (r.cover) {
    figures = CoverFigures(*r.cover);
    if (const std::optional<double> over =
            CoverDeltaOverInput(r.cover->certificate.delta, g.mesh_report)) {
      figures.emplace_back("delta_input", *over);
    }
  }
  if (r.kind == SphereSetKind::kInternal) {
    if (const std::optional<double> over = InternalProtrusionOverInput(g.mesh_report)) {
      figures.emplace_back("protrusion_input", *over);
    }
  }
  for (const auto& [name, value] : figures) {
    std::visit([&summary, &name = name](const auto& v) { summary[name] = v; }, value);
  }
  if (options.remote.enabled()) {
    summary["server"] = options.remote.server;
    summary["sphere_set_key"] = g.sphere_set_key;
    summary["cache"] = g.cache;
  }
  if (!options.output_path.empty()) summary["output"] = options.output_path;
  std::cout << summary.dump() << "\n";
}

// One line on stderr: what was made, in how long, and where it came from on a cache hit.
void PrintLine(const GenerateCliOptions& options, const Generated& g) {
  const GeneratedSphereSet& r = g.result;
  std::string line = absl::StrFormat("inscribe: %d %s spheres for %s", r.set.spheres.size(),
                                     SphereSetKindName(r.kind), options.mesh_path);
  if (r.cover) {
    absl::StrAppendFormat(&line, ", delta %.4g", r.cover->certificate.delta);
  } else if (r.quality) {
    absl::StrAppendFormat(&line, ", nerr %.4g", r.quality->nerr);
  }
  if (g.cache.empty() || g.cache == "computed" || g.cache == "joined") {
    absl::StrAppendFormat(&line, " in %.2f s", g.call_seconds);
  } else {
    absl::StrAppendFormat(&line, " from the server's %s cache in %.2f s (computed in %.2f s)",
                          g.cache, g.call_seconds, r.generation_seconds);
  }
  std::cerr << line << "\n";
}

absl::Status RunGenerate(const GenerateCliOptions& options) {
  if (absl::Status output = CheckSphereOutputFormat(options.output_path, options.format);
      !output.ok()) {
    return output;
  }
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  absl::StatusOr<Generated> generated = Generate((*session)->client(), options);
  if (!generated.ok()) return generated.status();

  // The sphere file goes to -o, else to stdout unless --json claims stdout for the summary
  // (as with deform).
  const SphereFile file = GenerationSphereFile(options.parameters, generated->result,
                                               generated->mesh_sha256, generated->mesh_report);
  if (absl::Status written =
          EmitSphereFile(file, options.output_path, options.format, options.json, options.link);
      !written.ok()) {
    return written;
  }
  if (options.json) {
    PrintSummary(options, *generated);
  } else {
    PrintLine(options, *generated);
  }
  return absl::OkStatus();
}

}  // namespace

void AddGenerateCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<GenerateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "generate",
      "Approximate a closed mesh by internal medial spheres (at most one per voxel), dilated "
      "ones, or a certified cover; prints the sphere-set JSON unless -o or --json says "
      "otherwise");
  cmd->add_option("MESH", options->mesh_path, "Mesh file (.off, .obj, .stl, .ply)")->required();
  CLI::Option* voxel = cmd->add_option("--voxel-size", options->parameters.voxel_size,
                                       "Voxel side sigma, mesh units");
  CLI::Option* budget = cmd->add_option(
      "--max-spheres", options->parameters.max_spheres,
      "Finest voxel grid giving at most N spheres (default mode, N = 500); the search's runs "
      "count in the reported time. With --cover: at most N spheres, the smallest delta reached");
  voxel->excludes(budget);
  budget->excludes(voxel);
  CLI::Option* selection =
      cmd->add_option_function<std::string>(
             "--selection",
             [options](const std::string& name) {
               absl::StatusOr<SphereSelection> parsed = ParseSphereSelection(name);
               if (!parsed.ok()) throw CLI::ValidationError(std::string(parsed.status().message()));
               options->parameters.selection = *parsed;
             },
             "How the sphere budget is spent: paper (the finest voxel grid within it, one sphere "
             "per voxel) or optimised (the spheres of a finer grid's pool that cover the most "
             "volume)")
          ->default_str(SphereSelectionName(kDefaultSphereSelection));
  selection->excludes(voxel);
  CLI::Option* cover = cmd->add_flag_callback(
      "--cover", [options] { options->parameters.kind = SphereSetKind::kCover; },
      "Make a certified cover instead: spheres proven to hold the whole solid, with delta, a "
      "sound bound on how far they reach outside it (written to the file's stats); no contacts");
  CLI::Option* protrusion =
      cmd->add_option("--max-protrusion", options->parameters.max_protrusion,
                      "With --cover, instead of --max-spheres: delta at most D mesh units, with "
                      "the fewest spheres");
  protrusion->needs(cover)->excludes(budget)->excludes(voxel);
  budget->excludes(protrusion);
  voxel->excludes(protrusion);
  cover->excludes(voxel);
  voxel->excludes(cover);
  selection->excludes(cover);
  cmd->add_option("--cover-resolution", options->parameters.cover_resolution,
                  "With --cover: the certificate's finest cell side, as a fraction of the "
                  "largest bounding-box side")
      ->needs(cover)
      ->capture_default_str();
  // The medial-sphere options: covers choose from balls of their own.
  std::vector<CLI::Option*> medial_options;
  medial_options.push_back(
      cmd->add_option("--object-angle", options->parameters.medial.object_angle,
                      "Drop medial points with a smaller object angle, radians in (0, pi)")
          ->capture_default_str());
  medial_options.push_back(
      cmd->add_option("--epsilon", options->parameters.medial.epsilon,
                      "Centres within this of the medial surface, mesh units (default 1e-4 of the "
                      "bounding-box diagonal)"));
  medial_options.push_back(cmd->add_option("--samples", options->parameters.medial.samples,
                                           "Sample points per voxel on its circumscribed sphere")
                               ->capture_default_str());
  medial_options.push_back(
      cmd->add_option("--screen-samples", options->parameters.medial.screen_samples,
                      "Samples tried first per voxel; 0 = every voxel gets the full set")
          ->capture_default_str());
  medial_options.push_back(
      cmd->add_flag("!--no-corner-screen", options->parameters.medial.corner_screen,
                    "Sample every voxel, not only those whose corners' boundary directions differ "
                    "by about the object angle"));
  medial_options.push_back(
      cmd->add_option("--pair-angle-margin", options->parameters.medial.pair_angle_margin,
                      "Skip face-face sample pairs whose angle is below the object angle minus "
                      "this, radians (default pi: search every crossing pair; 0.1 speeds up "
                      "faceted tubes)"));
  medial_options.push_back(
      cmd->add_flag("--subdivide-boundary", options->parameters.medial.subdivide_boundary,
                    "Split voxels the boundary may cross into 8 (up to 8 spheres there)"));
  medial_options.push_back(cmd->add_option("--max-voxels", options->parameters.medial.max_voxels,
                                           "Refuse grids with more voxels than this")
                               ->capture_default_str());
  for (CLI::Option* medial : medial_options) medial->excludes(cover);
  cmd->add_option("--quality-samples", options->parameters.quality.surface_samples,
                  "Boundary samples for coverage and Hausdorff distance in the stats")
      ->capture_default_str();
  cmd->add_option("-o,--output", options->output_path,
                  "Write the sphere set here (format from --format or the extension)")
      ->check(WritableFile());
  cmd->add_option("--format", options->format, "Sphere file format")
      ->check(CLI::IsMember({"json", "sph", "csv", "obj", "yaml", "yml"}, CLI::ignore_case));
  cmd->add_option("--link", options->link,
                  "cuRobo YAML output: the link name the spheres are listed under (default mesh)");
  cmd->add_flag_callback(
         "--dilate", [options] { options->parameters.kind = SphereSetKind::kDilated; },
         "Grow the spheres to cover more of the boundary (conservative dilation, S_D+); they "
         "then protrude, contacts are not written and nerr is a lower bound")
      ->excludes(cover);
  cmd->add_option("--dilation-growth", options->parameters.dilation.growth,
                  "With --dilate: the fraction of the paper's growth each sphere makes (1 = "
                  "the paper's S_D+; 0.5 halved the distance error on 5 of 6 Table II models)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  AddSolidLoadOptions(cmd, &options->load);
  cmd->add_flag("--json", options->json,
                "Print one JSON summary on stdout (spheres, voxel_size, seconds, volumes, nerr, "
                "quality figures)");
  AddRemoteOptions(cmd, &options->remote, 600.0);
  SetExitStatusHelp(cmd, "the mesh cannot be used");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunGenerate(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
