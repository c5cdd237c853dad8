// JSON forms of core results, as the CLI prints them.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "inscribe/mesh_validation.h"

namespace inscribe::cli {

// The `inscribe info --json` object: mesh_sha256, vertices, triangles, closed, usable,
// volume, bbox {min, max, diagonal}, counts {...}, issues [...].
nlohmann::json MeshReportJson(const MeshReport& report, const std::string& sha256);

}  // namespace inscribe::cli
