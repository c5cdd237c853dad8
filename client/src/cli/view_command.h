// `inscribe view MESH SPHERES [-o report.html]`: one self-contained HTML page showing the mesh
// and the spheres in 3D (three.js, embedded) with the quality report and the paper's Fig. 7
// histograms of signed distances between the boundary and the spheres' envelope.
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddViewCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
