#include "sphere_output.h"

#include <iostream>

#include "absl/strings/str_format.h"
#include "command_outcome.h"
#include "output_files.h"

namespace inscribe::cli {

absl::Status EmitSphereFile(const SphereFile& file, const std::string& output_path,
                            const std::string& format, bool json_summary,
                            const std::string& yaml_link) {
  SphereFileWriteOptions write;
  if (!yaml_link.empty()) write.yaml_link_name = yaml_link;
  if (!output_path.empty()) {
    if (!format.empty()) write.format = *ParseSphereFileFormat(format);
    if (absl::Status status = WriteSphereFile(output_path, file, write); !status.ok()) {
      return BadInputError(status.message());
    }
    const absl::StatusOr<SphereFileFormat> chosen =
        write.format ? *write.format : SphereFileFormatFromPath(output_path);
    ReportWritten(output_path, absl::StrFormat("%d spheres, %s", file.set.spheres.size(),
                                               chosen.ok() ? SphereFileFormatName(*chosen) : "?"));
    return absl::OkStatus();
  }
  if (json_summary) return absl::OkStatus();
  const SphereFileFormat chosen =
      format.empty() ? SphereFileFormat::kJson : *ParseSphereFileFormat(format);
  absl::StatusOr<std::string> bytes = FormatSphereFile(file, chosen, write);
  if (!bytes.ok()) return UnusableMeshError(bytes.status().message());
  std::cout << *bytes;
  if (!bytes->empty() && bytes->back() != '\n') std::cout << "\n";
  return absl::OkStatus();
}

}  // namespace inscribe::cli
