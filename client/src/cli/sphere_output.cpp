#include "sphere_output.h"

#include <iostream>

#include "exit_codes.h"

namespace inscribe::cli {

int EmitSphereFile(const SphereFile& file, const std::string& output_path,
                   const std::string& format, bool json_summary, const std::string& yaml_link) {
  SphereFileWriteOptions write;
  if (!yaml_link.empty()) write.yaml_link_name = yaml_link;
  if (!output_path.empty()) {
    if (!format.empty()) write.format = *ParseSphereFileFormat(format);
    if (absl::Status status = WriteSphereFile(output_path, file, write); !status.ok()) {
      std::cerr << "inscribe: " << status.message() << "\n";
      return kExitBadInput;
    }
    return kExitOk;
  }
  if (json_summary) return kExitOk;
  const SphereFileFormat chosen =
      format.empty() ? SphereFileFormat::kJson : *ParseSphereFileFormat(format);
  absl::StatusOr<std::string> bytes = FormatSphereFile(file, chosen, write);
  if (!bytes.ok()) {
    std::cerr << "inscribe: " << bytes.status().message() << "\n";
    return kExitUnusableMesh;
  }
  std::cout << *bytes;
  if (!bytes->empty() && bytes->back() != '\n') std::cout << "\n";
  return kExitOk;
}

}  // namespace inscribe::cli
