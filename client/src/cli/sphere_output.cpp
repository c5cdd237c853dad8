#include "sphere_output.h"

#include <iostream>

#include "command_outcome.h"

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
