// inscribe.SphereSet: core's SphereSet with what Python users carry along with it.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <vector>

#include "inscribe/balls/sphere_io.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::python {

namespace py = pybind11;

struct PySphereSet {
  SphereSet set;
  std::string kind;                      // "internal", "dilated", "cover", or "" when not known
  std::string mesh_sha256;               // "sha256:<hex>" of the mesh the set approximates, or ""
  NamedValues params;                    // as a sphere file's params (generation settings)
  NamedValues stats;                     // as a sphere file's stats (figures about the run)
  std::optional<QualityReport> quality;  // when generated with evaluation
  std::optional<CoverCertificate> certificate;  // a generated cover's
  // The spheres moved by Deformer.update, each sphere's index in the reference set.
  std::vector<std::int32_t> reference_index;
};

// The spheres of an inscribe.SphereSet, or of a C-contiguous (N, 4) float64 array [x, y, z, r]
// (each sphere checked by CheckSphere); TypeError / ValueError otherwise.
std::vector<Sphere> SpheresOf(py::handle spheres);

}  // namespace inscribe::python
