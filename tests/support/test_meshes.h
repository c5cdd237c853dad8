// Where tests find CGAL's demo meshes (fetched by scripts/fetch-meshes into data/).
#pragma once

#include <string>

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

// Absolute path of data/<name> (or $INSCRIBE_DATA_DIR/<name>); "" if the file is missing.
std::string TestMeshPath(const std::string& name);

// Reads and prepares data/<name>; fails the calling test (ASSERT) on any error.
Mesh LoadTestMesh(const std::string& name);

}  // namespace inscribe::testing

// Skips the test, loudly, when a demo mesh is missing: this only happens when Debian's
// libcgal-demo package cannot be had (scripts/fetch-meshes failed).
#define INSCRIBE_REQUIRE_MESH(name)                                                          \
  do {                                                                                       \
    if (::inscribe::testing::TestMeshPath(name).empty()) {                                   \
      GTEST_SKIP() << "\n\n*** SKIPPED: test mesh '" << (name)                               \
                   << "' is missing. Run scripts/fetch-meshes (needs Debian's libcgal-demo " \
                      "package). ***\n";                                                     \
    }                                                                                        \
  } while (0)
