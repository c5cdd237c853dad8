// Where a subcommand's sphere file goes: shared by generate and deform.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "inscribe/balls/sphere_io.h"

namespace inscribe::cli {

// Writes `file` to `output_path` (format from `format`, else the extension) when one is given;
// otherwise prints it on stdout (format `format`, default JSON) unless `json_summary` claims
// stdout for a summary. Fails with BadInputError (the file cannot be written) or
// UnusableMeshError (the set cannot be put in that format). `format` has been checked by the
// command line.
// `yaml_link` names the link cuRobo YAML output lists the spheres under (empty: "mesh").
absl::Status EmitSphereFile(const SphereFile& file, const std::string& output_path,
                            const std::string& format, bool json_summary,
                            const std::string& yaml_link = "");

}  // namespace inscribe::cli
