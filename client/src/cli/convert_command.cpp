#include "convert_command.h"

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/strings/str_join.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/robot_spheres.h"
#include "output_files.h"
#include "robot_sphere_files.h"
#include "sphere_output.h"

namespace inscribe::cli {
namespace {

struct ConvertCliOptions {
  std::string input_path;
  std::string output_path;
  std::string from;  // input format; empty: ReadSphereFile's choice (extension, else sniffed)
  std::string to;    // output format; empty: from the output's extension, else JSON
  int sph_level = -1;
  double scale = 1.0;     // centres and radii multiplied by it (ScaledSphereFile)
  std::string link;       // the cuRobo YAML link to read
  std::string yaml_link;  // the cuRobo YAML link to write under
  std::string robot;      // the URDF that urdf and morphit output is written into
  bool json = false;
};

// Whether the run converts a whole robot's spheres (robot_spheres.h) rather than one set: a
// robot format named by --to / --from or by either file's extension.
bool IsRobotConversion(const ConvertCliOptions& options) {
  return RobotFormatNamed(options.to) || RobotFormatNamed(options.from) ||
         RobotFormatOfPath(options.output_path) || RobotFormatOfPath(options.input_path) ||
         !options.robot.empty();
}

absl::Status RunRobotConvert(const ConvertCliOptions& options) {
  if (!options.link.empty() || !options.yaml_link.empty() || options.sph_level != -1) {
    return UsageError(
        "--link, --yaml-link and --sph-level pick one sphere set; a robot conversion keeps "
        "every link");
  }
  if (options.scale != 1.0) {
    return UsageError(
        "--scale converts one sphere set; a robot's spheres are in its links' frames, in "
        "metres: scale the robot's meshes (URDF <mesh scale>) and spherize it again");
  }
  if (options.json && options.output_path.empty()) {
    return UsageError("--json prints a summary on stdout, so it needs -o for the file");
  }
  absl::StatusOr<robot::RobotSpheresFormat> to = RobotOutputFormat(options.to, options.output_path);
  if (!to.ok()) return to.status();
  std::optional<robot::RobotSpheresFormat> from;
  if (!options.from.empty()) from = *robot::ParseRobotSpheresFormat(options.from);
  robot::RobotSpheresFormat read_as = robot::RobotSpheresFormat::kCurobo;
  absl::StatusOr<robot::RobotSpheres> model =
      robot::ReadRobotSpheresFile(options.input_path, from, &read_as);
  if (!model.ok()) return BadInputError(model.status().message());
  // A URDF layout is rewritten into itself unless another robot is named.
  std::string base = options.robot;
  if (base.empty() && (read_as == robot::RobotSpheresFormat::kUrdf ||
                       read_as == robot::RobotSpheresFormat::kMorphit)) {
    base = options.input_path;
  }
  bool merged = false;
  if (absl::Status written =
          WriteRobotSpheres(*model, *to, options.output_path, base,
                            "inscribe convert from " + options.input_path, &merged);
      !written.ok()) {
    return written;
  }
  const std::vector<std::string> dropped = NoteDroppedParts(*model, *to);
  std::size_t spheres = 0;
  for (const LinkSpheres& link : model->links) spheres += link.spheres.size();
  if (options.json) {
    nlohmann::json summary;
    summary["input"] = options.input_path;
    summary["from"] = robot::RobotSpheresFormatName(read_as);
    summary["output"] = options.output_path;
    summary["format"] = robot::RobotSpheresFormatName(*to);
    summary["links"] = model->links.size();
    summary["spheres"] = spheres;
    summary["ignored_pairs"] = model->self_collision_ignore.size();
    summary["merged"] = merged;
    summary["left_out"] = dropped;
    std::cout << summary.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else if (!options.output_path.empty()) {
    std::cout << "wrote " << model->links.size() << " links, " << spheres << " spheres, "
              << model->self_collision_ignore.size() << " ignored pairs to " << options.output_path
              << " (" << robot::RobotSpheresFormatName(*to)
              << (merged ? ", merged into the SRDF there" : "") << ") from "
              << robot::RobotSpheresFormatName(read_as) << "\n";
  }
  return absl::OkStatus();
}

// What the output format leaves out of `file`, e.g. {"contacts", "params"}: only JSON keeps
// more than the spheres.
std::vector<std::string> DroppedParts(const SphereFile& file, SphereFileFormat to) {
  std::vector<std::string> dropped;
  if (to == SphereFileFormat::kJson) return dropped;
  if (!file.set.contacts.empty()) dropped.push_back("contacts (deform needs them)");
  if (!file.mesh_sha256.empty()) dropped.push_back("mesh hash");
  if (!file.params.empty()) dropped.push_back("params");
  if (!file.stats.empty()) dropped.push_back("stats");
  return dropped;
}

absl::Status RunConvert(const ConvertCliOptions& options) {
  if (IsRobotConversion(options)) return RunRobotConvert(options);
  if (options.json && options.output_path.empty()) {
    return UsageError("--json prints a summary on stdout, so it needs -o for the file");
  }
  // The output format, settled before anything is read: an unknown extension is a usage error.
  SphereFileFormat to = SphereFileFormat::kJson;
  if (!options.to.empty()) {
    to = *ParseSphereFileFormat(options.to);
  } else if (!options.output_path.empty()) {
    absl::StatusOr<SphereFileFormat> by_extension = SphereFileFormatFromPath(options.output_path);
    if (!by_extension.ok()) {
      return UsageError(std::string(by_extension.status().message()) +
                        "; name the format with --to");
    }
    to = *by_extension;
  }

  // Written under the link it was read from, unless told otherwise.
  const std::string yaml_link = !options.yaml_link.empty() ? options.yaml_link : options.link;
  if (to == SphereFileFormat::kYaml && !yaml_link.empty()) {
    if (absl::Status name = FormatCuroboYaml({LinkSpheres{yaml_link, {}}}).status(); !name.ok()) {
      return UsageError(name.message());
    }
  }

  SphereFileReadOptions read;
  if (!options.from.empty()) read.format = *ParseSphereFileFormat(options.from);
  read.sph_level = options.sph_level;
  read.yaml_link = options.link;
  absl::StatusOr<SphereFile> file = ReadSphereFile(options.input_path, read);
  if (!file.ok()) return BadInputError(file.status().message());
  // What scaling drops (it describes the unscaled mesh), then what the format leaves out.
  std::vector<std::string> scaled_away;
  if (options.scale != 1.0) {
    if (!file->mesh_sha256.empty()) scaled_away.push_back("mesh hash");
    if (!file->params.empty()) scaled_away.push_back("params");
    if (!file->stats.empty()) scaled_away.push_back("stats (a certificate among them)");
    if (!file->protrusions.empty()) scaled_away.push_back("protrusions");
    file = ScaledSphereFile(*std::move(file), options.scale);
    if (!file.ok()) return UsageError(std::string(file.status().message()) + " (--scale)");
    if (!scaled_away.empty()) {
      std::cerr << "inscribe: note: --scale " << options.scale
                << " drops what describes the unscaled mesh: " << absl::StrJoin(scaled_away, ", ")
                << "\n";
    }
  }
  if (absl::Status written =
          EmitSphereFile(*file, options.output_path, std::string(SphereFileFormatName(to)),
                         /*json_summary=*/false, yaml_link);
      !written.ok()) {
    return written;
  }

  const std::vector<std::string> dropped = DroppedParts(*file, to);
  if (!dropped.empty()) {
    std::cerr << "inscribe: note: " << SphereFileFormatName(to)
              << " holds only the spheres; left out: " << absl::StrJoin(dropped, ", ") << "\n";
  }
  if (options.json) {
    nlohmann::json summary;
    summary["input"] = options.input_path;
    summary["output"] = options.output_path;
    summary["format"] = SphereFileFormatName(to);
    summary["spheres"] = file->set.spheres.size();
    summary["mesh_sha256"] = file->mesh_sha256;
    summary["left_out"] = dropped;
    summary["scale"] = options.scale;
    summary["dropped_by_scale"] = scaled_away;
    std::cout << summary.dump() << "\n";
  } else if (!options.output_path.empty()) {
    std::cout << "wrote " << file->set.spheres.size() << " spheres to " << options.output_path
              << " (" << SphereFileFormatName(to) << ")\n";
  }
  return absl::OkStatus();
}

}  // namespace

void AddConvertCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<ConvertCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "A sphere file in another format: inscribe JSON, spheretree .sph, CSV, cuRobo YAML, or "
      "OBJ meshes of the spheres; or a robot's spheres between planner formats (cuRobo's "
      "robot configuration, XRDF, SRDF, spherized URDF as VAMP reads it, MorphIt's URDF), "
      "saying what the target leaves out; the spheres are copied bit for bit");
  cmd->add_option("SPHERES", options->input_path,
                  "Sphere file (.json, .sph, .csv, cuRobo .yml/.yaml), or a robot's (.yml, .xrdf, "
                  ".srdf, .urdf)")
      ->required();
  cmd->add_option("-o,--output", options->output_path,
                  "Output file, written atomically (default: stdout)")
      ->check(WritableFile());
  cmd->add_option("--from", options->from, "Input format (default: from extension or content)")
      ->check(CLI::IsMember({"json", "sph", "csv", "yaml", "yml", "curobo", "xrdf", "srdf", "urdf",
                             "vamp", "morphit"},
                            CLI::ignore_case));
  cmd->add_option("--to", options->to,
                  "Output format (default: from -o's extension, else json); a robot's: curobo, "
                  "xrdf, srdf, urdf (VAMP's layout), morphit")
      ->check(CLI::IsMember({"json", "sph", "csv", "obj", "yaml", "yml", "curobo", "xrdf", "srdf",
                             "urdf", "vamp", "morphit"},
                            CLI::ignore_case));
  cmd->add_option("--robot", options->robot,
                  "Robot conversions to urdf or morphit: the robot's URDF the spheres are written "
                  "into (default: the input, when it is a URDF)");
  cmd->add_option("--sph-level", options->sph_level, ".sph tree level to read (-1 = the leaves)")
      ->capture_default_str();
  cmd->add_option("--link", options->link,
                  "cuRobo YAML with several links: the link to read (also the link written)");
  cmd->add_option("--yaml-link", options->yaml_link,
                  "Link name the spheres are listed under in YAML output (default: --link, "
                  "else mesh)");
  cmd->add_option("--scale", options->scale,
                  "Multiply centres and radii by S (0.001: spheres of a millimetre mesh in "
                  "metres); drops the mesh hash, params and certificate, which name the "
                  "unscaled mesh")
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "Print one JSON summary on stdout (needs -o)");
  SetExitStatusHelp(cmd, "");
  cmd->callback([options, outcome] { outcome->status = RunConvert(*options); });
}

}  // namespace inscribe::cli
