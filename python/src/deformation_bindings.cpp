// inscribe.Deformer: medial spheres that follow a deforming mesh (paper Section V).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <optional>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "deformation_results.h"
#include "inscribe/medial/sphere_deformation.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

// SphereDeformer is not thread-safe and its calls run without the GIL, so Python threads
// sharing one Deformer take turns here.
struct LockedDeformer {
  explicit LockedDeformer(SphereDeformer d) : deformer(std::move(d)) {}
  SphereDeformer deformer;
  std::mutex mutex;
};

}  // namespace

DeformationOptions DeformationOptionsOf(std::optional<double> xi, bool strict,
                                        bool interpolated_normal) {
  DeformationOptions options;
  if (xi) options.xi = *xi;
  options.strict = strict;
  if (interpolated_normal) options.direction = ContactDirection::kInterpolatedNormal;
  return options;
}

std::shared_ptr<PySphereSet> DeformedSphereSet(DeformedSpheres moved) {
  auto set = std::make_shared<PySphereSet>();
  set->kind = "internal";
  set->set = std::move(moved.set);
  set->reference_index = std::move(moved.reference_index);
  set->stats = {{"xi", moved.xi},
                {"max_protrusion", moved.max_protrusion},
                {"shrunk", moved.shrunk},
                {"dropped", moved.dropped},
                {"closest_point_queries", moved.closest_point_queries},
                {"max_shrink_steps", std::int64_t{moved.max_shrink_steps}},
                {"seconds", moved.seconds}};
  return set;
}

void BindDeformation(py::module_& m) {
  py::class_<DeformationErrorBounds>(m, "DeformationErrorBounds",
                                     "Bounds on nerr of spheres against a deformed solid "
                                     "(Lemmas 1 and 2; volumes in mesh units cubed).")
      .def_readonly("volume_mesh", &DeformationErrorBounds::volume_mesh)
      .def_readonly("volume_union", &DeformationErrorBounds::volume_union)
      .def_readonly("nerr_lower", &DeformationErrorBounds::nerr_lower)
      .def_readonly("nerr_upper", &DeformationErrorBounds::nerr_upper)
      .def_readonly("nerr_upper_uniform_xi", &DeformationErrorBounds::nerr_upper_uniform_xi)
      .def_readonly("uniform_xi_holds", &DeformationErrorBounds::uniform_xi_holds)
      .def_readonly("exact", &DeformationErrorBounds::exact)
      .def_readonly("seconds", &DeformationErrorBounds::seconds)
      .def("__repr__", [](const DeformationErrorBounds& b) {
        return absl::StrCat("DeformationErrorBounds(nerr_lower=", b.nerr_lower,
                            ", nerr_upper=", b.nerr_upper, ")");
      });

  py::class_<LockedDeformer, std::shared_ptr<LockedDeformer>>(
      m, "Deformer",
      "Moves a reference set of internal spheres (with contacts) onto deformed vertex "
      "positions of the same mesh; every update starts from the reference. Not thread-safe.")
      .def(py::init([](py::handle reference, const PySphereSet& spheres, std::optional<double> xi,
                       bool strict, bool interpolated_normal) {
             const DeformationOptions options =
                 DeformationOptionsOf(xi, strict, interpolated_normal);
             const std::shared_ptr<Solid> solid = SolidOf(reference);
             absl::StatusOr<SphereDeformer> deformer;
             {
               py::gil_scoped_release release;
               deformer = SphereDeformer::Create(solid->mesh(), spheres.set, options);
             }
             return std::make_shared<LockedDeformer>(ValueOrRaise(std::move(deformer)));
           }),
           py::arg("reference"), py::arg("spheres"), py::kw_only(), py::arg("xi") = py::none(),
           py::arg("strict") = false, py::arg("interpolated_normal") = false,
           "Deformer(reference, spheres, *, xi=None, strict=False, interpolated_normal=False): "
           "reference a Mesh or Solid (validated here: contacts index the validated mesh, as "
           "generate's do); spheres an internal SphereSet with contacts. xi: Algorithm 1's "
           "threshold in mesh units (None: 0.25% of the largest bounding-box extent).")
      .def_property_readonly(
          "xi", [](const LockedDeformer& d) { return d.deformer.options().xi; },
          "the threshold in use, mesh units")
      .def(
          "update",
          [](LockedDeformer& locked, py::handle vertices) {
            py::array_t<double> v = RequireMatrix<double>(vertices, 3, "vertices");
            Vertices deformed(v.shape(0), 3);
            if (v.size() > 0) std::memcpy(deformed.data(), v.data(), v.size() * sizeof(double));
            absl::StatusOr<DeformedSpheres> moved;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(locked.mutex);
              moved = locked.deformer.Update(deformed);
            }
            return DeformedSphereSet(ValueOrRaise(std::move(moved)));
          },
          py::arg("vertices"),
          "The spheres on `vertices` ((V, 3) float64, the reference's vertex order and count; "
          "mesh units): a SphereSet with contacts, .reference_index, and .stats (xi, "
          "max_protrusion, shrunk, dropped, seconds). ValueError for a wrong count, "
          "non-finite or inverted vertices (the deformer is then unchanged).")
      .def(
          "bounds",
          [](LockedDeformer& locked, py::handle spheres) {
            const std::vector<Sphere> balls = SpheresOf(spheres);
            absl::StatusOr<DeformationErrorBounds> bounds;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(locked.mutex);
              bounds = BoundDeformationError(locked.deformer.oracle(), balls,
                                             locked.deformer.options().xi);
            }
            return ValueOrRaise(std::move(bounds));
          },
          py::arg("spheres"),
          "Lemma 1 and 2 bounds on nerr of `spheres` against the mesh of the last update "
          "(exact union volumes; slower than update).");
}

}  // namespace inscribe::python
