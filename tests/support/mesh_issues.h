// Questions tests ask of a validation report.
#pragma once

#include <string>

#include "inscribe/solid/mesh_validation.h"

namespace inscribe::testing {

// True when `report` lists an issue with this code and severity.
inline bool HasIssue(const MeshReport& report, const std::string& code, Severity severity) {
  for (const MeshIssue& issue : report.issues) {
    if (issue.code == code && issue.severity == severity) return true;
  }
  return false;
}

}  // namespace inscribe::testing
