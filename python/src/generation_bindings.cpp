// inscribe.generate, inscribe.evaluate, inscribe.certify and their reports.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "generation_arguments.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "interruptible.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

std::shared_ptr<PySphereSet> Generate(
    py::handle mesh_or_solid, std::optional<std::int64_t> max_spheres,
    std::optional<double> voxel_size, const std::string& kind, std::optional<double> object_angle,
    std::optional<double> epsilon, std::optional<int> samples,
    std::optional<bool> subdivide_boundary, std::optional<std::int64_t> max_voxels,
    std::optional<double> dilation_growth, std::optional<double> max_protrusion,
    std::optional<double> cover_resolution, bool evaluate,
    std::optional<std::int64_t> quality_samples, const std::optional<std::string>& selection,
    const py::object& progress) {
  const SphereSetParameters parameters =
      SphereSetParametersOf({max_spheres, voxel_size, kind, object_angle, epsilon, samples,
                             subdivide_boundary, max_voxels, dilation_growth, max_protrusion,
                             cover_resolution, evaluate, quality_samples, selection});

  const std::shared_ptr<Solid> solid = SolidOf(mesh_or_solid);
  absl::StatusOr<GeneratedSphereSet> generated;
  OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
    generated = GenerateSphereSet(*solid, parameters, control);
    return generated.status();
  }));

  // The params and stats a sphere file records of a generation: the same as `inscribe
  // generate` writes.
  SphereFile file = GenerationSphereFile(parameters, *generated, solid->sha256, solid->report);
  auto result = std::make_shared<PySphereSet>();
  result->kind = SphereSetKindName(generated->kind);
  result->mesh_sha256 = std::move(file.mesh_sha256);
  result->set = std::move(generated->set);
  result->params = std::move(file.params);
  result->stats = std::move(file.stats);
  result->quality = generated->quality;
  if (generated->cover) result->certificate = generated->cover->certificate;
  return result;
}

// generate's docstring, with core's defaults.
const std::string& GenerateDoc() {
  static const std::string doc = [] {
    const MedialSphereOptions medial;
    return absl::StrCat(R"doc(Spheres for a closed mesh: the pipeline `inscribe generate` runs.

mesh: an inscribe.Solid (inscribe.prepare(mesh), reusable), or a mesh validated and
    prepared on each call: an inscribe.Mesh, a path, a (vertices, faces) pair of arrays or an
    object with .vertices and .faces (trimesh.Trimesh).
max_spheres: at most N spheres, spent as `selection` says (internal, dilated), or the
    smallest protrusion reached with N (cover). voxel_size: sigma, the voxel side in
    mesh units (internal, dilated only). At most one of the two; neither: a budget of )doc",
                        kDefaultMaxSpheres, R"doc(.
selection: how a budget is spent (internal, dilated): 'paper' - the finest voxel grid
    giving at most N, one sphere per voxel; 'optimised' - the N spheres of a finer grid's
    pool that cover the most volume. None: ')doc",
                        SphereSelectionName(kDefaultSphereSelection), R"doc('.
kind: 'internal' - medial spheres inside the solid, tangent to it, with contacts (for
    Deformer); 'dilated' - grown to cover more of the boundary (they protrude);
    'cover' - a certified cover holding the whole solid (.certificate.delta bounds how far
    it reaches outside, mesh units).
object_angle (radians, in (0, pi); default )doc",
                        medial.object_angle, R"doc(), epsilon (mesh
    units; default 1e-4 of the bounding-box diagonal), samples (per voxel; default )doc",
                        medial.samples, R"doc(), subdivide_boundary, max_voxels:
    medial-sphere settings (not for covers). dilation_growth in [0, 1] (dilated).
    max_protrusion (mesh units, cover: the fewest spheres with delta at most this, instead of
    a budget), cover_resolution (the certificate's finest cell, a fraction of the largest
    bounding-box side). None means core's default for every one of them.
evaluate: compute .quality (exact union volume, surface samples; quality_samples of them).
progress: a callable, called on this thread with the fraction done in [0, 1], or a
    progress bar (tqdm.tqdm(total=100)) advanced to that fraction of its total. Ctrl-C
    cancels the run (KeyboardInterrupt) within about 50 ms of the core noticing.

Returns a SphereSet: .spheres (N, 4) float64 [x, y, z, r] in the mesh's units and frame,
.kind, .mesh_sha256 (the validated mesh's), .quality, .certificate (covers), .stats.
The same mesh and settings give the same spheres bit for bit as `inscribe generate`.
Raises ValueError for bad settings (the message names the field), inscribe.Error with code
FAILED_PRECONDITION for a mesh that is not a usable solid, RESOURCE_EXHAUSTED when no grid
fits the budget. The GIL is released while it runs.)doc");
  }();
  return doc;
}

}  // namespace

void BindGeneration(py::module_& m) {
  py::class_<QualityReport>(m, "QualityReport",
                            "Quality of a sphere set against its solid (lengths in mesh units, "
                            "volumes in mesh units cubed).")
      .def_readonly("spheres", &QualityReport::spheres)
      .def_readonly("volume_mesh", &QualityReport::volume_mesh)
      .def_readonly("volume_union", &QualityReport::volume_union,
                    "exact union-of-balls volume (not sampled)")
      .def_readonly("nerr", &QualityReport::nerr,
                    "Err / vol(mesh): exact when no sphere protrudes, else a lower bound")
      .def_readonly("nerr_is_exact", &QualityReport::nerr_is_exact)
      .def_readonly("protrusion_max", &QualityReport::protrusion_max)
      .def_readonly("protrusion_mean", &QualityReport::protrusion_mean)
      .def_readonly("protrusion_p95", &QualityReport::protrusion_p95)
      .def_readonly("protruding_spheres", &QualityReport::protruding_spheres)
      .def_readonly("protrusion_tolerance", &QualityReport::protrusion_tolerance)
      .def_readonly("bbox_diagonal", &QualityReport::bbox_diagonal)
      .def_readonly("surface_samples", &QualityReport::surface_samples)
      .def_readonly("coverage", &QualityReport::coverage,
                    "fraction of boundary samples within coverage_tolerance of the union")
      .def_readonly("coverage_tolerance", &QualityReport::coverage_tolerance)
      .def_readonly("boundary_to_union_mean", &QualityReport::boundary_to_union_mean)
      .def_readonly("boundary_to_union_hausdorff", &QualityReport::boundary_to_union_hausdorff)
      .def_readonly("radius_min", &QualityReport::radius_min)
      .def_readonly("radius_max", &QualityReport::radius_max)
      .def_readonly("fat_up_to_voxel_size", &QualityReport::fat_up_to_voxel_size)
      .def_readonly("voxel_size", &QualityReport::voxel_size)
      .def_readonly("fat", &QualityReport::fat)
      .def_readonly("fraction_radius_over_sqrt3_sigma",
                    &QualityReport::fraction_radius_over_sqrt3_sigma)
      .def_readonly("seconds", &QualityReport::seconds)
      .def("__repr__", [](const QualityReport& q) {
        return absl::StrCat("QualityReport(spheres=", q.spheres, ", nerr=", q.nerr,
                            ", protrusion_max=", q.protrusion_max, ", coverage=", q.coverage, ")");
      });

  py::class_<CoverCertificate>(m, "CoverCertificate",
                               "Whether a sphere set provably holds the whole solid, and how far "
                               "it reaches outside it (mesh units).")
      .def_readonly("certified", &CoverCertificate::certified,
                    "every point of the solid lies in some sphere (a proof)")
      .def_readonly("mesh_sha256", &CoverCertificate::mesh_sha256,
                    "'sha256:<hex>' of the validated mesh it was proved against")
      .def_readonly("spheres_sha256", &CoverCertificate::spheres_sha256,
                    "'sha256:<hex>' of the spheres it was proved for, in their order")
      .def_readonly("delta", &CoverCertificate::delta,
                    "no point of any sphere lies farther than this outside the solid")
      .def_readonly("resolution", &CoverCertificate::resolution, "finest cell side, mesh units")
      .def_readonly("cells", &CoverCertificate::cells)
      .def_readonly("cells_in_sphere", &CoverCertificate::cells_in_sphere)
      .def_readonly("cells_outside", &CoverCertificate::cells_outside)
      .def_readonly("failed_cells", &CoverCertificate::failed_cells)
      .def_property_readonly(
          "uncovered_point",
          [](const CoverCertificate& c) -> py::object {
            if (!c.uncovered_point) return py::none();
            return py::array_t<double>(3, c.uncovered_point->data());
          },
          "(3,) float64 point of the solid in no sphere (the disproof), or None")
      .def_readonly("uncovered_depth", &CoverCertificate::uncovered_depth)
      .def_readonly("uncovered_gap", &CoverCertificate::uncovered_gap)
      .def_readonly("seconds", &CoverCertificate::seconds)
      .def_property_readonly(
          "protrusions",
          [](const CoverCertificate& c) {
            return py::array_t<double>(static_cast<py::ssize_t>(c.protrusions.size()),
                                       c.protrusions.data());
          },
          "(N,) float64 per sphere: radius less the centre's depth, rounded up (delta is the "
          "largest); the cores CertifiedObject adds to the internal spheres")
      .def("__repr__", [](const CoverCertificate& c) {
        return absl::StrCat("CoverCertificate(certified=", c.certified ? "True" : "False",
                            ", delta=", c.delta, ")");
      });

  m.def("generate", &Generate, py::arg("mesh"), py::kw_only(), py::arg("max_spheres") = py::none(),
        py::arg("voxel_size") = py::none(), py::arg("kind") = "internal",
        py::arg("object_angle") = py::none(), py::arg("epsilon") = py::none(),
        py::arg("samples") = py::none(), py::arg("subdivide_boundary") = py::none(),
        py::arg("max_voxels") = py::none(), py::arg("dilation_growth") = py::none(),
        py::arg("max_protrusion") = py::none(), py::arg("cover_resolution") = py::none(),
        py::arg("evaluate") = true, py::arg("quality_samples") = py::none(),
        py::arg("selection") = py::none(), py::arg("progress") = py::none(), GenerateDoc().c_str());

  m.def(
      "evaluate",
      [](py::handle mesh_or_solid, py::handle spheres, std::optional<std::int64_t> surface_samples,
         std::optional<double> voxel_size, std::optional<double> coverage_tolerance,
         std::optional<std::uint64_t> seed) {
        QualityOptions options;
        Override(options.surface_samples, surface_samples);
        Override(options.voxel_size, voxel_size);
        Override(options.coverage_tolerance, coverage_tolerance);
        Override(options.seed, seed);
        OkOrRaise(CheckQualityOptions(options));
        const std::shared_ptr<Solid> solid = SolidOf(mesh_or_solid);
        const std::vector<Sphere> balls = SpheresOf(spheres);
        absl::StatusOr<QualityReport> report;
        {
          py::gil_scoped_release release;
          report = EvaluateSpheres(solid->oracle, balls, options);
        }
        return ValueOrRaise(std::move(report));
      },
      py::arg("mesh"), py::arg("spheres"), py::kw_only(), py::arg("surface_samples") = py::none(),
      py::arg("voxel_size") = py::none(), py::arg("coverage_tolerance") = py::none(),
      py::arg("seed") = py::none(),
      "Quality of `spheres` (a SphereSet or an (N, 4) float64 array) against the solid of "
      "`mesh` (Mesh or Solid): exact nerr, protrusion, coverage, Hausdorff distance, fatness "
      "(QualityReport; mesh units). None: core's defaults (100,000 surface samples).");

  m.def(
      "certify",
      [](py::handle mesh_or_solid, py::handle spheres, std::optional<double> resolution,
         std::optional<bool> stop_at_witness, const py::object& progress) {
        CoverCertifyOptions options;
        Override(options.resolution, resolution);
        Override(options.stop_at_witness, stop_at_witness);
        OkOrRaise(CheckCoverCertifyOptions(options));
        const std::shared_ptr<Solid> solid = SolidOf(mesh_or_solid);
        const std::vector<Sphere> balls = SpheresOf(spheres);
        absl::StatusOr<CoverCertificate> certificate;
        OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
          certificate = CertifyCover(*solid, balls, options, control);
          return certificate.status();
        }));
        return *std::move(certificate);
      },
      py::arg("mesh"), py::arg("spheres"), py::kw_only(), py::arg("resolution") = py::none(),
      py::arg("stop_at_witness") = py::none(), py::arg("progress") = py::none(),
      "Proves whether `spheres` (SphereSet or (N, 4) float64) contain the whole solid of "
      "`mesh` (CoverCertificate: certified, delta in mesh units, or an uncovered point). "
      "resolution: the finest cell side as a fraction of the largest bounding-box side "
      "(default 1/2048). Ctrl-C cancels (KeyboardInterrupt).");
}

}  // namespace inscribe::python
