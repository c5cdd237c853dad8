// Writing meshes with CGAL's writers: an independent path for testing inscribe's readers.
#pragma once

#include <string>

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

// Writes `mesh` to `path` with CGAL::IO::write_polygon_soup (format from the extension;
// binary STL/PLY when `binary`), 17 significant digits in text. False if CGAL fails.
bool WriteMeshWithCgal(const std::string& path, const Mesh& mesh, bool binary);

}  // namespace inscribe::testing
