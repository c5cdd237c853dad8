// `inscribe evaluate --certify ROBOT SPHERES`: a robot's sphere file (any planner format,
// robot_spheres.h) checked link by link against the robot's own geometry, each element through
// the service's CertifyCover, combined per link by robot::CombineElementCovers.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "inscribe/client/client.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::cli {

// Whether `path` names a robot description rather than a mesh: .urdf, .xml or .mjcf.
bool IsRobotDescriptionPath(const std::string& path);

struct RobotCertifyOptions {
  std::string robot_path;      // URDF or MJCF
  std::string spheres_path;    // any robot sphere format
  std::string spheres_format;  // empty: by extension and content
  std::vector<std::string> package_paths;
  CoverCertifyOptions certify;
  RepairOptions repair;
  bool json = false;
  std::string server;  // for the JSON report; empty in embedded mode
};

// Prints one row per link with geometry or spheres (a table, or one JSON object) and returns
// OK when every link with geometry is a certified cover; UnusableMeshError naming how many are
// not; BadInputError for unreadable files, a sphere file naming links the robot lacks.
absl::Status RunRobotCertify(const client::Client& client, const RobotCertifyOptions& options);

}  // namespace inscribe::cli
