// `inscribe distance A B --poses FILE`: separation distance between two sphere sets, B placed
// by each pose relative to A (paper Section VI).
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

void AddDistanceCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
