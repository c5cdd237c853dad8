#include "generate_command.h"

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "absl/strings/str_format.h"
#include "exit_codes.h"
#include "inscribe/medial_spheres.h"
#include "inscribe/sphere_dilation.h"
#include "inscribe/sphere_io.h"
#include "inscribe/sphere_quality.h"
#include "progress_bar.h"
#include "remote_options.h"
#include "report_json.h"
#include "solid_loading.h"
#include "sphere_output.h"

namespace inscribe::cli {
namespace {

constexpr std::int64_t kDefaultMaxSpheres = 500;

struct GenerateCliOptions {
  std::string mesh_path;
  std::optional<double> voxel_size;
  std::optional<std::int64_t> max_spheres;
  MedialSphereOptions medial;
  std::int64_t quality_samples = 100'000;
  std::string output_path;
  std::string format;
  std::string link;  // cuRobo YAML link name
  bool json = false;
  bool fill_holes = false;
  bool dilate = false;
  DilationOptions dilation;
  RemoteOptions remote;
};

// What generate reports, made here or by the server. The server does not send the search's
// and the grid's statistics, nor the dilation's: those stay empty in remote mode.
struct Generated {
  SphereSet set;  // S_D, or S_D+ with --dilate
  std::string mesh_sha256;
  std::int64_t triangles = 0;  // of the validated mesh
  double voxel_size = 0.0;     // sigma used (the search's choice with --max-spheres)
  double epsilon = 0.0;        // resolved from the default, mesh units
  QualityReport quality;
  double seconds = 0.0;       // generation (remote: the server's whole computation)
  double load_seconds = 0.0;  // reading and validation (remote: and the upload)
  std::optional<int> runs;    // generation runs of the --max-spheres search (1 with sigma)
  std::optional<MedialSphereStats> stats;
  std::optional<DilationResult> dilation;
  // Remote mode only: the server's key of the set and where it came from ("computed",
  // "memory", "disk", "joined").
  std::string sphere_set_key, cache;
};

// What --dilate adds to the file's stats and the JSON summary (mesh units, seconds).
NamedValues DilationStats(const DilationResult& dilation) {
  return {{"v_points", dilation.v_points},
          {"edge_points", dilation.edge_points},
          {"grown", dilation.grown},
          {"max_growth", dilation.max_growth},
          {"dilation_seconds", dilation.seconds}};
}

// Params and stats of the sphere file (DESIGN.md section 3), in mesh units and radians.
SphereFile MakeSphereFile(const GenerateCliOptions& options, const Generated& g) {
  SphereFile file;
  file.set = g.set;
  file.mesh_sha256 = g.mesh_sha256;
  file.params = {
      {"voxel_size", g.voxel_size},
      {"object_angle", options.medial.object_angle},
      {"epsilon", g.epsilon},
      {"samples", static_cast<std::int64_t>(options.medial.samples)},
      {"screen_samples", static_cast<std::int64_t>(options.medial.screen_samples)},
      {"pair_angle_margin", options.medial.pair_angle_margin},
      {"corner_screen", options.medial.corner_screen},
      {"subdivide_boundary", options.medial.subdivide_boundary},
  };
  if (options.max_spheres) file.params.emplace_back("max_spheres", *options.max_spheres);
  if (options.dilate) {
    file.params.emplace_back("dilated", true);
    file.params.emplace_back("dilation_growth", options.dilation.growth);
  }
  const QualityReport& quality = g.quality;
  file.stats = {{"seconds", g.seconds}};
  if (g.runs) file.stats.emplace_back("search_runs", static_cast<std::int64_t>(*g.runs));
  NamedValues figures = {
      {"volume_mesh", quality.volume_mesh},
      {"volume_union", quality.volume_union},
      {"nerr", quality.nerr},
      {"nerr_is_exact", quality.nerr_is_exact},
      {"protrusion_max", quality.protrusion_max},
      {"coverage", quality.coverage},
      {"boundary_to_union_hausdorff", quality.boundary_to_union_hausdorff},
      {"surface_samples", quality.surface_samples},
      {"fat", quality.fat},
  };
  if (g.stats) {
    figures.emplace_back("visited_voxels", g.stats->visited_voxels);
    figures.emplace_back("closest_point_queries", g.stats->closest_point_queries);
  }
  if (g.dilation) {
    for (auto& stat : DilationStats(*g.dilation)) figures.push_back(std::move(stat));
  }
  for (auto& figure : figures) file.stats.push_back(std::move(figure));
  return file;
}

// Embedded mode: the core in this process. Prints why and sets *exit_code on failure.
std::optional<Generated> GenerateHere(GenerateCliOptions options, int* exit_code) {
  std::optional<LoadedSolid> solid =
      LoadSolid(options.mesh_path, exit_code, LoadSolidOptions{options.fill_holes});
  if (!solid) return std::nullopt;

  ProgressBar progress("generating");
  GenerationControl control;
  control.on_progress = [&progress](double fraction) { progress.Update(fraction); };

  const auto start = std::chrono::steady_clock::now();
  MedialSphereResult result;
  Generated g;
  if (options.voxel_size) {
    options.medial.voxel_size = *options.voxel_size;
    absl::StatusOr<MedialSphereResult> run =
        GenerateMedialSpheres(solid->oracle, options.medial, control);
    if (!run.ok()) {
      std::cerr << "inscribe: " << run.status().message() << "\n";
      *exit_code = kExitUsage;
      return std::nullopt;
    }
    result = *std::move(run);
    g.runs = 1;
  } else {
    SphereBudgetOptions budget;
    budget.max_spheres = *options.max_spheres;
    budget.base = options.medial;
    absl::StatusOr<SphereBudgetResult> search =
        GenerateWithSphereBudget(solid->oracle, budget, control);
    if (!search.ok()) {
      std::cerr << "inscribe: " << search.status().message() << "\n";
      *exit_code = search.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage
                                                                                : kExitUnusableMesh;
      return std::nullopt;
    }
    g.runs = search->runs;
    result = std::move(search->best);
  }
  g.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // S_D+ (Section VI-A) replaces S_D from here on: it is what gets evaluated and written.
  if (options.dilate) {
    absl::StatusOr<DilationResult> dilated =
        DilateSpheres(solid->oracle, result.set, options.dilation);
    if (!dilated.ok()) {
      std::cerr << "inscribe: dilating the spheres: " << dilated.status().message() << "\n";
      *exit_code = kExitUnusableMesh;
      return std::nullopt;
    }
    result.set = dilated->set;
    g.dilation = *std::move(dilated);
  }

  QualityOptions quality_options;
  quality_options.surface_samples = options.quality_samples;
  quality_options.voxel_size = result.voxel_size;
  absl::StatusOr<QualityReport> quality =
      EvaluateSpheres(solid->oracle, result.set.spheres, quality_options);
  if (!quality.ok()) {
    std::cerr << "inscribe: evaluating the result: " << quality.status().message() << "\n";
    *exit_code = kExitUnusableMesh;
    return std::nullopt;
  }
  g.set = std::move(result.set);
  g.mesh_sha256 = solid->sha256;
  g.triangles = solid->report.triangles;
  g.voxel_size = result.voxel_size;
  g.epsilon = result.epsilon;
  g.quality = *std::move(quality);
  g.load_seconds = solid->seconds;
  g.stats = result.stats;
  return g;
}

// The options the server's GenerateParameters cannot carry: it always uses the core's defaults
// for these (and its own --max-voxels). Returns the first one set otherwise, or "".
std::string OptionTheServerCannotTake(const GenerateCliOptions& options) {
  const MedialSphereOptions defaults;
  if (options.medial.screen_samples != defaults.screen_samples) return "--screen-samples";
  if (options.medial.corner_screen != defaults.corner_screen) return "--no-corner-screen";
  if (options.medial.pair_angle_margin != defaults.pair_angle_margin) {
    return "--pair-angle-margin";
  }
  if (options.medial.max_voxels != defaults.max_voxels) {
    return "--max-voxels (the server's own --max-voxels applies)";
  }
  if (options.quality_samples != QualityOptions().surface_samples) return "--quality-samples";
  // 0 means the paper's full growth (1) on the wire.
  if (options.dilate && options.dilation.growth == 0.0) return "--dilation-growth 0";
  return "";
}

// Remote mode: PutMesh, then Generate with the progress bar fed by the server's messages.
std::optional<Generated> GenerateRemotely(const GenerateCliOptions& options, int* exit_code) {
  const std::optional<client::Client> made = MakeClientOrReport(options.remote, exit_code);
  if (!made) return std::nullopt;
  const client::Client& client = *made;
  std::optional<UploadedSolid> solid =
      UploadSolid(client, options.remote, options.mesh_path, exit_code, {options.fill_holes});
  if (!solid) return std::nullopt;

  client::GenerateSettings settings;
  settings.voxel_size = options.voxel_size.value_or(0.0);
  settings.max_spheres = options.max_spheres.value_or(0);
  settings.object_angle = options.medial.object_angle;
  settings.epsilon = options.medial.epsilon;
  settings.samples = options.medial.samples;
  settings.subdivide_boundary = options.medial.subdivide_boundary;
  settings.dilate = options.dilate;
  settings.dilation_growth = options.dilate ? options.dilation.growth : 0.0;
  settings.fill_holes = options.fill_holes;
  ProgressBar progress("generating");
  client::GenerateOptions call;
  call.on_progress = [&progress](double fraction) { progress.Update(fraction); };
  absl::StatusOr<client::GenerateResult> result = client.Generate(solid->sha256, settings, call);
  // Evicted between the two calls (a busy server with a small cache): upload and ask again.
  if (result.status().code() == absl::StatusCode::kNotFound) {
    result = client.Generate(solid->mesh, settings, call);
  }
  if (!result.ok()) {
    const int code = ReportRemoteError(result.status(), options.remote);
    // Bad parameters are a usage error, as in embedded mode.
    *exit_code = result.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage : code;
    return std::nullopt;
  }
  if (!result->quality) {
    std::cerr << "inscribe: the server sent no quality report (server " << options.remote.server
              << ")\n";
    *exit_code = kExitInternal;
    return std::nullopt;
  }
  Generated g;
  g.set = std::move(result->spheres);
  g.mesh_sha256 = std::move(result->mesh_sha256);
  g.triangles = solid->report.triangles;
  g.voxel_size = result->voxel_size;
  // The core's default, resolved as GenerateMedialSpheres does (the server does not send it).
  g.epsilon =
      options.medial.epsilon > 0.0 ? options.medial.epsilon : 1e-4 * solid->report.bbox.diagonal();
  g.quality = *std::move(result->quality);
  g.seconds = result->seconds;
  g.load_seconds = solid->seconds;
  g.sphere_set_key = std::move(result->sphere_set_key);
  g.cache = std::move(result->cache);
  return g;
}

void PrintSummary(const GenerateCliOptions& options, const Generated& g) {
  nlohmann::json summary = QualityReportJson(g.quality);
  summary["mesh"] = options.mesh_path;
  summary["mesh_sha256"] = g.mesh_sha256;
  summary["triangles"] = g.triangles;
  summary["voxel_size"] = g.voxel_size;
  summary["object_angle"] = options.medial.object_angle;
  summary["epsilon"] = g.epsilon;
  summary["samples"] = options.medial.samples;
  summary["subdivide_boundary"] = options.medial.subdivide_boundary;
  if (options.max_spheres) summary["max_spheres"] = *options.max_spheres;
  if (g.runs) summary["search_runs"] = *g.runs;
  summary["seconds"] = g.seconds;
  summary["load_seconds"] = g.load_seconds;
  if (g.stats) {
    summary["visited_voxels"] = g.stats->visited_voxels;
    summary["screened_voxels"] = g.stats->screened_voxels;
    summary["closest_point_queries"] = g.stats->closest_point_queries;
  }
  summary["dilated"] = options.dilate;
  if (g.dilation) {
    for (const auto& [name, value] : DilationStats(*g.dilation)) {
      std::visit([&summary, &name = name](const auto& v) { summary[name] = v; }, value);
    }
  }
  if (options.remote.enabled()) {
    summary["server"] = options.remote.server;
    summary["sphere_set_key"] = g.sphere_set_key;
    summary["cache"] = g.cache;
  }
  if (!options.output_path.empty()) summary["output"] = options.output_path;
  std::cout << summary.dump() << "\n";
}

int RunGenerate(GenerateCliOptions options) {
  if (!options.voxel_size && !options.max_spheres) options.max_spheres = kDefaultMaxSpheres;
  int exit_code = kExitOk;
  std::optional<Generated> generated;
  if (options.remote.enabled()) {
    if (const std::string option = OptionTheServerCannotTake(options); !option.empty()) {
      std::cerr << "inscribe: " << option << " cannot be used with --server\n";
      return kExitUsage;
    }
    generated = GenerateRemotely(options, &exit_code);
  } else {
    generated = GenerateHere(options, &exit_code);
  }
  if (!generated) return exit_code;

  // The sphere file goes to -o, else to stdout unless --json claims stdout for the summary
  // (as with deform).
  const SphereFile file = MakeSphereFile(options, *generated);
  if (const int code =
          EmitSphereFile(file, options.output_path, options.format, options.json, options.link);
      code != kExitOk) {
    return code;
  }
  if (options.json) PrintSummary(options, *generated);
  return kExitOk;
}

}  // namespace

void AddGenerateCommand(CLI::App& app, int* exit_code) {
  auto options = std::make_shared<GenerateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "generate",
      "Approximate a closed mesh by internal medial spheres (at most one per voxel); prints "
      "the sphere-set JSON unless -o or --json says otherwise");
  cmd->add_option("MESH", options->mesh_path, "Mesh file (.off, .obj, .stl, .ply)")->required();
  CLI::Option* voxel =
      cmd->add_option("--voxel-size", options->voxel_size, "Voxel side sigma, mesh units");
  CLI::Option* budget = cmd->add_option(
      "--max-spheres", options->max_spheres,
      "Finest voxel grid giving at most N spheres (default mode, N = 500); the search's runs "
      "count in the reported time");
  voxel->excludes(budget);
  budget->excludes(voxel);
  cmd->add_option("--object-angle", options->medial.object_angle,
                  "Drop medial points with a smaller object angle, radians in (0, pi)")
      ->capture_default_str();
  cmd->add_option("--epsilon", options->medial.epsilon,
                  "Centres within this of the medial surface, mesh units (default 1e-4 of the "
                  "bounding-box diagonal)");
  cmd->add_option("--samples", options->medial.samples,
                  "Sample points per voxel on its circumscribed sphere")
      ->capture_default_str();
  cmd->add_option("--screen-samples", options->medial.screen_samples,
                  "Samples tried first per voxel; 0 = every voxel gets the full set")
      ->capture_default_str();
  cmd->add_flag("!--no-corner-screen", options->medial.corner_screen,
                "Sample every voxel, not only those whose corners' boundary directions differ "
                "by about the object angle");
  cmd->add_option("--pair-angle-margin", options->medial.pair_angle_margin,
                  "Skip face-face sample pairs whose angle is below the object angle minus "
                  "this, radians (default pi: search every crossing pair; 0.1 speeds up "
                  "faceted tubes)");
  cmd->add_flag("--subdivide-boundary", options->medial.subdivide_boundary,
                "Split voxels the boundary may cross into 8 (up to 8 spheres there)");
  cmd->add_option("--max-voxels", options->medial.max_voxels,
                  "Refuse grids with more voxels than this")
      ->capture_default_str();
  cmd->add_option("--quality-samples", options->quality_samples,
                  "Boundary samples for coverage and Hausdorff distance in the stats")
      ->capture_default_str();
  cmd->add_option("-o,--output", options->output_path,
                  "Write the sphere set here (format from --format or the extension)");
  cmd->add_option("--format", options->format, "Sphere file format")
      ->check(CLI::IsMember({"json", "sph", "csv", "obj", "yaml", "yml"}, CLI::ignore_case));
  cmd->add_option("--link", options->link,
                  "cuRobo YAML output: the link name the spheres are listed under (default mesh)");
  cmd->add_flag("--dilate", options->dilate,
                "Grow the spheres to cover more of the boundary (conservative dilation, S_D+); "
                "they then protrude, contacts are not written and nerr is a lower bound");
  cmd->add_option("--dilation-growth", options->dilation.growth,
                  "With --dilate: the fraction of the paper's growth each sphere makes (1 = "
                  "the paper's S_D+; 0.5 halved the distance error on 5 of 6 Table II models)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("--fill-holes", options->fill_holes,
                "Close the mesh's holes first (see inscribe info --fill-holes)");
  cmd->add_flag("--json", options->json,
                "Print one JSON summary on stdout (spheres, voxel_size, seconds, volumes, nerr, "
                "quality figures)");
  AddRemoteOptions(cmd, &options->remote, 600.0);
  cmd->callback([options, exit_code] { *exit_code = RunGenerate(*options); });
}

}  // namespace inscribe::cli
