// `inscribe urdf ROBOT.urdf [--package-path DIR ...] [--max-spheres-per-link N | --voxel-size S]
// -o OUT [--yaml PATH] [--json]`: every link's collision geometry (visual when it has none)
// approximated by spheres in the link's frame; writes the URDF with sphere collisions and
// cuRobo's collision_spheres YAML. Links that cannot be spherized are named, kept as they
// were, and make the exit status 1; the outputs are still written for the other links.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddUrdfCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
