// `inscribe deform REFERENCE_MESH SPHERES DEFORMED_MESH`: moves a generated sphere set onto a
// deformed version of its mesh (paper Section V) and bounds the new set's volumetric error.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

void AddDeformCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
