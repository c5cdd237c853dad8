// The `inscribe` command line. Each subcommand lives in its own *_command.cpp; each runs in this
// process, or on an inscribed server with --server ADDR (see remote_options.h).
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "convert_command.h"
#include "deform_command.h"
#include "distance_command.h"
#include "evaluate_command.h"
#include "exit_codes.h"
#include "generate_command.h"
#include "health_command.h"
#include "info_command.h"
#include "stats_command.h"
#include "urdf_command.h"
#include "view_command.h"

int main(int argc, char** argv) {
  CLI::App app{"inscribe: approximate closed triangle meshes by unions of medial spheres"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "inscribe 0.1.0");
  app.footer(
      "Exit status: 0 done; 1 the mesh cannot be used; 2 missing, unreadable or malformed "
      "input; 64 bad command line; 69 the --server could not be reached or did not answer "
      "within --timeout; 70 internal error; 77 the --server refused the call (missing or wrong "
      "--token-file, UNAUTHENTICATED or PERMISSION_DENIED).");
  int exit_code = inscribe::cli::kExitOk;
  inscribe::cli::AddInfoCommand(app, &exit_code);
  inscribe::cli::AddGenerateCommand(app, &exit_code);
  inscribe::cli::AddEvaluateCommand(app, &exit_code);
  inscribe::cli::AddDeformCommand(app, &exit_code);
  inscribe::cli::AddDistanceCommand(app, &exit_code);
  inscribe::cli::AddStatsCommand(app, &exit_code);
  inscribe::cli::AddHealthCommand(app, &exit_code);
  inscribe::cli::AddUrdfCommand(app, &exit_code);
  inscribe::cli::AddViewCommand(app, &exit_code);
  inscribe::cli::AddConvertCommand(app, &exit_code);
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
  return exit_code;
}
