#include "generate_command.h"

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
  bool json = false;
  bool fill_holes = false;
  bool dilate = false;
  DilationOptions dilation;
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
// With --dilate, `result.set` holds the grown spheres (no contacts) and `dilation` is set.
SphereFile MakeSphereFile(const LoadedSolid& solid, const GenerateCliOptions& options,
                          const MedialSphereResult& result, const QualityReport& quality,
                          double seconds, int runs, const std::optional<DilationResult>& dilation) {
  SphereFile file;
  file.set = result.set;
  file.mesh_sha256 = solid.sha256;
  file.params = {
      {"voxel_size", result.voxel_size},
      {"object_angle", options.medial.object_angle},
      {"epsilon", result.epsilon},
      {"samples", static_cast<std::int64_t>(options.medial.samples)},
      {"screen_samples", static_cast<std::int64_t>(options.medial.screen_samples)},
      {"pair_angle_margin", options.medial.pair_angle_margin},
      {"corner_screen", options.medial.corner_screen},
      {"subdivide_boundary", options.medial.subdivide_boundary},
  };
  if (options.max_spheres) file.params.emplace_back("max_spheres", *options.max_spheres);
  if (dilation) {
    file.params.emplace_back("dilated", true);
    file.params.emplace_back("dilation_growth", options.dilation.growth);
  }
  file.stats = {
      {"seconds", seconds},
      {"search_runs", static_cast<std::int64_t>(runs)},
      {"volume_mesh", quality.volume_mesh},
      {"volume_union", quality.volume_union},
      {"nerr", quality.nerr},
      {"nerr_is_exact", quality.nerr_is_exact},
      {"protrusion_max", quality.protrusion_max},
      {"coverage", quality.coverage},
      {"boundary_to_union_hausdorff", quality.boundary_to_union_hausdorff},
      {"surface_samples", quality.surface_samples},
      {"fat", quality.fat},
      {"visited_voxels", result.stats.visited_voxels},
      {"closest_point_queries", result.stats.closest_point_queries},
  };
  if (dilation) {
    for (auto& stat : DilationStats(*dilation)) file.stats.push_back(std::move(stat));
  }
  return file;
}

int RunGenerate(GenerateCliOptions options) {
  int exit_code = kExitOk;
  std::optional<LoadedSolid> solid =
      LoadSolid(options.mesh_path, &exit_code, LoadSolidOptions{options.fill_holes});
  if (!solid) return exit_code;

  ProgressBar progress("generating");
  GenerationControl control;
  control.on_progress = [&progress](double fraction) { progress.Update(fraction); };

  const auto start = std::chrono::steady_clock::now();
  MedialSphereResult result;
  int runs = 1;
  if (options.voxel_size) {
    options.medial.voxel_size = *options.voxel_size;
    absl::StatusOr<MedialSphereResult> run =
        GenerateMedialSpheres(solid->oracle, options.medial, control);
    if (!run.ok()) {
      std::cerr << "inscribe: " << run.status().message() << "\n";
      return kExitUsage;
    }
    result = *std::move(run);
  } else {
    SphereBudgetOptions budget;
    budget.max_spheres = options.max_spheres.value_or(kDefaultMaxSpheres);
    options.max_spheres = budget.max_spheres;
    budget.base = options.medial;
    absl::StatusOr<SphereBudgetResult> search =
        GenerateWithSphereBudget(solid->oracle, budget, control);
    if (!search.ok()) {
      std::cerr << "inscribe: " << search.status().message() << "\n";
      return search.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage
                                                                          : kExitUnusableMesh;
    }
    runs = search->runs;
    result = std::move(search->best);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // S_D+ (Section VI-A) replaces S_D from here on: it is what gets evaluated and written.
  std::optional<DilationResult> dilation;
  if (options.dilate) {
    absl::StatusOr<DilationResult> dilated =
        DilateSpheres(solid->oracle, result.set, options.dilation);
    if (!dilated.ok()) {
      std::cerr << "inscribe: dilating the spheres: " << dilated.status().message() << "\n";
      return kExitUnusableMesh;
    }
    result.set = dilated->set;
    dilation = *std::move(dilated);
  }

  QualityOptions quality_options;
  quality_options.surface_samples = options.quality_samples;
  quality_options.voxel_size = result.voxel_size;
  absl::StatusOr<QualityReport> quality =
      EvaluateSpheres(solid->oracle, result.set.spheres, quality_options);
  if (!quality.ok()) {
    std::cerr << "inscribe: evaluating the result: " << quality.status().message() << "\n";
    return kExitUnusableMesh;
  }
  const SphereFile file =
      MakeSphereFile(*solid, options, result, *quality, seconds, runs, dilation);

  // The sphere file goes to -o, else to stdout unless --json claims stdout for the summary
  // (as with deform).
  if (const int code = EmitSphereFile(file, options.output_path, options.format, options.json);
      code != kExitOk) {
    return code;
  }
  if (options.json) {
    nlohmann::json summary = QualityReportJson(*quality);
    summary["mesh"] = options.mesh_path;
    summary["mesh_sha256"] = solid->sha256;
    summary["triangles"] = solid->report.triangles;
    summary["voxel_size"] = result.voxel_size;
    summary["object_angle"] = options.medial.object_angle;
    summary["epsilon"] = result.epsilon;
    summary["samples"] = options.medial.samples;
    summary["subdivide_boundary"] = options.medial.subdivide_boundary;
    if (options.max_spheres) summary["max_spheres"] = *options.max_spheres;
    summary["search_runs"] = runs;
    summary["seconds"] = seconds;
    summary["load_seconds"] = solid->seconds;
    summary["visited_voxels"] = result.stats.visited_voxels;
    summary["screened_voxels"] = result.stats.screened_voxels;
    summary["closest_point_queries"] = result.stats.closest_point_queries;
    summary["dilated"] = dilation.has_value();
    if (dilation) {
      for (const auto& [name, value] : DilationStats(*dilation)) {
        std::visit([&summary, &name = name](const auto& v) { summary[name] = v; }, value);
      }
    }
    if (!options.output_path.empty()) summary["output"] = options.output_path;
    std::cout << summary.dump() << "\n";
  }
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
  cmd->callback([options, exit_code] { *exit_code = RunGenerate(*options); });
}

}  // namespace inscribe::cli
