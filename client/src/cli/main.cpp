// The `inscribe` command line. Each subcommand lives in its own *_command.cpp and returns an
// absl::Status; this prints a failure once and maps it to the exit status once
// (command_outcome.h). The service commands run on an inscribed server with --server ADDR, or
// on the same service in this process (service_session.h).
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "command_outcome.h"
#include "convert_command.h"
#include "deform_command.h"
#include "distance_command.h"
#include "evaluate_command.h"
#include "generate_command.h"
#include "health_command.h"
#include "info_command.h"
#include "scene_command.h"
#include "stats_command.h"
#include "urdf_command.h"
#include "view_command.h"

int main(int argc, char** argv) {
  CLI::App app{"inscribe: approximate closed triangle meshes by unions of medial spheres"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "inscribe 0.1.0");
  app.footer(
      "Exit status: 0 done; 1 the mesh cannot be used (evaluate --certify: the spheres are "
      "not a certified cover); 2 missing, unreadable or malformed "
      "input; 64 bad command line; 69 the --server could not be reached or did not answer "
      "within --timeout; 70 internal error; 77 the --server refused the call (missing or wrong "
      "--token-file, UNAUTHENTICATED or PERMISSION_DENIED).");
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return inscribe::cli::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "inscribe: internal error: " << e.what() << "\n";
    return inscribe::cli::kExitInternal;
  }
  return inscribe::cli::ReportOutcome(outcome);
}
