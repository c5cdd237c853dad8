// `inscribe distance A B --poses FILE`: separation distance between two sphere sets, B placed
// by each pose relative to A (paper Section VI).
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

void AddDistanceCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
