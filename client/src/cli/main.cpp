// The `inscribe` command line. Each subcommand lives in its own *_command.cpp and returns an
// absl::Status; this prints a failure once and maps it to the exit status once
// (command_outcome.h). The service commands run on an inscribed server with --server ADDR, or
// on the same service in this process (service_session.h).
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli_help.h"
#include "command_outcome.h"
#include "convert_command.h"
#include "deform_command.h"
#include "distance_command.h"
#include "evaluate_command.h"
#include "generate_command.h"
#include "health_command.h"
#include "info_command.h"
#include "output_files.h"
#include "progress_bar.h"
#include "scene_command.h"
#include "stats_command.h"
#include "urdf_command.h"
#include "view_command.h"

int main(int argc, char** argv) {
  CLI::App app{"inscribe: approximate closed triangle meshes by unions of medial spheres"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "inscribe " INSCRIBE_VERSION);
  app.footer("Each subcommand's --help lists its options and exit statuses.");
  inscribe::cli::SetProgressMode(inscribe::cli::ProgressModeFromEnvironment());
  // Taken before or after the subcommand (fallthrough): `inscribe generate m.off --progress`.
  app.add_flag_callback(
      "--progress", [] { inscribe::cli::SetProgressMode(inscribe::cli::ProgressMode::kLines); },
      "Report progress on stderr as plain lines when it is not a terminal (a log, CI); the "
      "same as INSCRIBE_PROGRESS=1 (0 turns progress off everywhere)");
  app.fallthrough();
  inscribe::cli::CommandOutcome outcome;
  inscribe::cli::AddInfoCommand(app, &outcome);
  inscribe::cli::AddGenerateCommand(app, &outcome);
  inscribe::cli::AddEvaluateCommand(app, &outcome);
  inscribe::cli::AddDeformCommand(app, &outcome);
  inscribe::cli::AddDistanceCommand(app, &outcome);
  inscribe::cli::AddSceneCommand(app, &outcome);
  inscribe::cli::AddStatsCommand(app, &outcome);
  inscribe::cli::AddHealthCommand(app, &outcome);
  inscribe::cli::AddUrdfCommand(app, &outcome);
  inscribe::cli::AddViewCommand(app, &outcome);
  inscribe::cli::AddConvertCommand(app, &outcome);
  if (const std::optional<std::string> unknown =
          inscribe::cli::UnknownSubcommandMessage(app, argc, argv)) {
    std::cerr << "inscribe: " << *unknown << "\n";
    return inscribe::cli::kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::vector<std::string> unknown = inscribe::cli::UnknownOptionMessages(app);
    if (unknown.empty()) {
      app.exit(e);
    } else {
      for (const std::string& message : unknown) std::cerr << message << "\n";
    }
    // An output that cannot be written is a file problem (2), like an input that cannot be
    // read, found here before any work.
    return inscribe::cli::OutputPathRefused() ? inscribe::cli::kExitBadInput
                                              : inscribe::cli::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "inscribe: internal error: " << e.what() << "\n";
    return inscribe::cli::kExitInternal;
  }
  return inscribe::cli::ReportOutcome(outcome);
}
