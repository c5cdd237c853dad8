// inscribe.Mesh, inscribe.load_mesh, validation reports and inscribe.Solid.
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

Mesh MeshFromArrays(py::handle vertices, py::handle triangles) {
  py::array_t<double> v = ConvertMatrix<double>(vertices, 3, "vertices");
  py::array_t<std::int32_t> t = ConvertMatrix<std::int32_t>(triangles, 3, "triangles");
  Mesh mesh;
  mesh.vertices.resize(v.shape(0), 3);
  mesh.triangles.resize(t.shape(0), 3);
  // The one copy (after ConvertMatrix's, for other dtypes): Mesh owns Eigen storage with the
  // same row-major layout.
  if (v.size() > 0) std::memcpy(mesh.vertices.data(), v.data(), v.size() * sizeof(double));
  if (t.size() > 0) std::memcpy(mesh.triangles.data(), t.data(), t.size() * sizeof(std::int32_t));
  return mesh;
}

py::object VerticesView(const Mesh& mesh, py::handle owner) {
  return ReadOnlyView(mesh.vertices.data(), mesh.num_vertices(), 3, 3 * sizeof(double), owner);
}

py::object TrianglesView(const Mesh& mesh, py::handle owner) {
  return ReadOnlyView(mesh.triangles.data(), mesh.num_triangles(), 3, 3 * sizeof(std::int32_t),
                      owner);
}

std::string ReportRepr(const MeshReport& report) {
  return absl::StrCat("MeshReport(vertices=", report.vertices, ", triangles=", report.triangles,
                      ", usable=", report.usable() ? "True" : "False", ", volume=", report.volume,
                      ", issues=", report.issues.size(), ")");
}

}  // namespace

void WarnAboutMesh(const MeshReport& report, const std::string& sha256) {
  const py::object warn = py::module_::import("warnings").attr("warn");
  const py::object category = py::module_::import("inscribe._inscribe").attr("MeshWarning");
  for (const MeshIssue& issue : report.notices()) {
    warn(absl::StrCat(SeverityName(issue.severity), ": ", issue.message), category, 2);
  }
  if (report.geometry_repaired()) {
    warn(absl::StrCat("results and certificates hold for the repaired mesh ", sha256,
                      ", not for the triangles as given (", report.repairs(), ")"),
         category, 2);
  }
}

RepairOptions RepairArgument(RepairOptions repair, bool fill_holes, double weld_tolerance) {
  if (fill_holes) {
    if (repair.level != MeshRepair::kSafe && repair.level != MeshRepair::kFill) {
      throw py::value_error(absl::StrCat("fill_holes=True asks for repair 'fill', but repair is '",
                                         MeshRepairName(repair.level), "': give one of them"));
    }
    repair.level = MeshRepair::kFill;
  }
  if (weld_tolerance != 0.0) {
    if (repair.weld_tolerance != 0.0 && repair.weld_tolerance != weld_tolerance) {
      throw py::value_error("weld_tolerance differs from repair.weld_tolerance: give one of them");
    }
    repair.weld_tolerance = weld_tolerance;
  }
  return repair;
}

std::shared_ptr<Solid> PrepareSolidReleasingGil(const Mesh& mesh, const RepairOptions& repair,
                                                bool check_self_intersections) {
  SolidOptions options;
  options.validate.repair = repair;
  options.validate.check_self_intersections = check_self_intersections;
  absl::StatusOr<Solid> solid;
  {
    py::gil_scoped_release release;
    solid = PrepareSolid(mesh, options);
  }
  auto prepared = std::make_shared<Solid>(ValueOrRaise(std::move(solid)));
  WarnAboutMesh(prepared->report, prepared->sha256);
  return prepared;
}

namespace {

bool IsPath(py::handle value) {
  return py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__");
}

std::shared_ptr<Mesh> LoadMesh(const std::string& path) {
  absl::StatusOr<Mesh> mesh;
  {
    py::gil_scoped_release release;
    mesh = ReadMesh(path);
  }
  return std::make_shared<Mesh>(ValueOrRaise(std::move(mesh)));
}

}  // namespace

std::string PathOf(py::handle path, const char* name) {
  if (!IsPath(path)) {
    throw py::type_error(absl::StrCat(name, " must be a str or os.PathLike, got ",
                                      std::string(py::str(py::type::of(path).attr("__name__")))));
  }
  return py::module_::import("os").attr("fsdecode")(path).cast<std::string>();
}

std::shared_ptr<Mesh> MeshOf(py::handle mesh) {
  if (py::isinstance<Mesh>(mesh)) return mesh.cast<std::shared_ptr<Mesh>>();
  if (IsPath(mesh)) return LoadMesh(PathOf(mesh, "mesh"));
  if ((py::isinstance<py::tuple>(mesh) || py::isinstance<py::list>(mesh)) && py::len(mesh) == 2) {
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(mesh);
    const py::object vertices = pair[0];
    const py::object faces = pair[1];
    return std::make_shared<Mesh>(MeshFromArrays(vertices, faces));
  }
  if (py::hasattr(mesh, "vertices") && py::hasattr(mesh, "faces")) {
    const py::object vertices = mesh.attr("vertices");
    const py::object faces = mesh.attr("faces");
    return std::make_shared<Mesh>(MeshFromArrays(vertices, faces));
  }
  throw py::type_error(absl::StrCat(
      "a mesh must be an inscribe.Mesh, a path, a (vertices, faces) pair or an object with "
      ".vertices and .faces (trimesh), got ",
      std::string(py::str(py::type::of(mesh).attr("__name__")))));
}

std::shared_ptr<Solid> SolidOf(py::handle mesh_or_solid) {
  if (py::isinstance<Solid>(mesh_or_solid)) return mesh_or_solid.cast<std::shared_ptr<Solid>>();
  return PrepareSolidReleasingGil(*MeshOf(mesh_or_solid), RepairOptions{}, true);
}

void BindMesh(py::module_& m) {
  // Issued (warnings.warn) for every warning and fix validation makes when a Solid is prepared.
  m.attr("MeshWarning") = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("inscribe.MeshWarning",
                                "A validation warning or fix of a mesh being prepared (see "
                                "MeshReport.issues); the spheres are still made.",
                                PyExc_UserWarning, nullptr));
  py::enum_<Severity>(m, "Severity", "How serious a MeshIssue is.")
      .value("ERROR", Severity::kError, "the mesh cannot be used to generate spheres")
      .value("WARNING", Severity::kWarning, "usable, but results may suffer")
      .value("FIXED", Severity::kFixed, "was wrong and has been repaired in the returned mesh");

  py::class_<RepairOptions>(
      m, "Repair",
      "How much validation may change a mesh to make it usable (core's RepairOptions). A level "
      "name ('none', 'safe', 'fill', 'wrap', 'auto') converts to Repair(level) wherever a repair "
      "is taken. none: identical vertices welded, orientation fixed; safe (the default): also "
      "duplicate triangles and walls stored twice removed, cracks welded within a tolerance from "
      "the mesh's size; fill: also holes closed; wrap: a watertight alpha wrap of all the "
      "triangles, enclosing every one of them; auto: safe, then fill, then wrap, until usable.")
      .def(py::init([](const std::string& level, double weld_tolerance, double wrap_alpha,
                       double wrap_offset) {
             RepairOptions repair;
             repair.level = ValueOrRaise(ParseMeshRepair(level));
             repair.weld_tolerance = weld_tolerance;
             repair.wrap_alpha = wrap_alpha;
             repair.wrap_offset = wrap_offset;
             return repair;
           }),
           py::arg("level") = "safe", py::kw_only(), py::arg("weld_tolerance") = 0.0,
           py::arg("wrap_alpha") = 0.0, py::arg("wrap_offset") = 0.0,
           absl::StrCat("weld_tolerance: also weld vertices this close (mesh units). wrap_alpha, "
                        "wrap_offset: the wrap's parameters (mesh units; 0: diagonal / ",
                        kWrapAlphaDivisor, " and alpha / ", kWrapOffsetDivisor, ").")
               .c_str())
      .def_property_readonly("level",
                             [](const RepairOptions& r) { return MeshRepairName(r.level); })
      .def_readonly("weld_tolerance", &RepairOptions::weld_tolerance)
      .def_readonly("wrap_alpha", &RepairOptions::wrap_alpha)
      .def_readonly("wrap_offset", &RepairOptions::wrap_offset)
      .def("__repr__", [](const RepairOptions& r) {
        return absl::StrCat("Repair('", MeshRepairName(r.level),
                            "', weld_tolerance=", r.weld_tolerance, ", wrap_alpha=", r.wrap_alpha,
                            ", wrap_offset=", r.wrap_offset, ")");
      });
  py::implicitly_convertible<py::str, RepairOptions>();

  py::class_<MeshIssue>(m, "MeshIssue", "One finding of mesh validation.")
      .def_readonly("severity", &MeshIssue::severity)
      .def_readonly("code", &MeshIssue::code, "stable identifier, e.g. 'not_closed'")
      .def_readonly("message", &MeshIssue::message, "one line a user can act on")
      .def_readonly("count", &MeshIssue::count)
      .def("__repr__", [](const MeshIssue& issue) {
        return absl::StrCat("MeshIssue(", SeverityName(issue.severity), ", '", issue.code, "', '",
                            issue.message, "')");
      });

  py::class_<MeshReport> report(m, "MeshReport",
                                "What validation found; counts are about the mesh as given "
                                "(before any fix) unless a field says otherwise.");
  report.def_readonly("vertices", &MeshReport::vertices)
      .def_readonly("triangles", &MeshReport::triangles)
      .def_readonly("non_finite_vertices", &MeshReport::non_finite_vertices)
      .def_readonly("out_of_range_indices", &MeshReport::out_of_range_indices)
      .def_readonly("degenerate_triangles", &MeshReport::degenerate_triangles)
      .def_readonly("duplicate_triangles", &MeshReport::duplicate_triangles)
      .def_readonly("unreferenced_vertices", &MeshReport::unreferenced_vertices)
      .def_readonly("border_edges", &MeshReport::border_edges)
      .def_readonly("non_manifold_edges", &MeshReport::non_manifold_edges)
      .def_readonly("non_manifold_vertices", &MeshReport::non_manifold_vertices)
      .def_readonly("inconsistent_edges", &MeshReport::inconsistent_edges)
      .def_readonly("components", &MeshReport::components)
      .def_readonly("flipped_triangles", &MeshReport::flipped_triangles)
      .def_readonly("flat_shells", &MeshReport::flat_shells,
                    "closed shells enclosing almost no volume (the exact inside test is used)")
      .def_readonly("self_intersections_checked", &MeshReport::self_intersections_checked)
      .def_readonly("self_intersecting_pairs", &MeshReport::self_intersecting_pairs)
      .def_readonly("welded_vertices", &MeshReport::welded_vertices)
      .def_readonly("weld_collapsed_triangles", &MeshReport::weld_collapsed_triangles)
      .def_readonly("weld_moved_within", &MeshReport::weld_moved_within,
                    "the weld tolerance when it was > 0 and merged vertices, else 0 (mesh units)")
      .def_readonly("holes_filled", &MeshReport::holes_filled)
      .def_readonly("hole_triangles_added", &MeshReport::hole_triangles_added)
      .def_readonly("duplicate_triangles_removed", &MeshReport::duplicate_triangles_removed)
      .def_readonly("double_walls_removed", &MeshReport::double_walls_removed,
                    "pairs of triangles with the same corners in opposite orders removed")
      .def_readonly("crack_weld_tolerance", &MeshReport::crack_weld_tolerance,
                    "the crack weld's tolerance (mesh units; 0 when the mesh had no border)")
      .def_readonly("crack_vertices_welded", &MeshReport::crack_vertices_welded)
      .def_readonly("wrapped", &MeshReport::wrapped,
                    "True when the mesh was replaced by its watertight alpha wrap")
      .def_readonly("wrap_alpha", &MeshReport::wrap_alpha)
      .def_readonly("wrap_offset", &MeshReport::wrap_offset)
      .def_readonly("wrap_input_triangles", &MeshReport::wrap_input_triangles)
      .def_readonly("wrap_triangles", &MeshReport::wrap_triangles)
      .def_readonly("wrap_reach", &MeshReport::wrap_reach,
                    "a proven bound on how far the wrap's surface is from the input triangles "
                    "(mesh units)")
      .def_readonly("volume", &MeshReport::volume,
                    "enclosed volume of the validated mesh, mesh units cubed")
      .def_property_readonly(
          "bbox_min", [](const MeshReport& r) { return py::array_t<double>(3, r.bbox.min.data()); },
          "(3,) float64: lower corner of the bounding box, mesh units")
      .def_property_readonly(
          "bbox_max", [](const MeshReport& r) { return py::array_t<double>(3, r.bbox.max.data()); },
          "(3,) float64: upper corner of the bounding box, mesh units")
      .def_readonly("issues", &MeshReport::issues)
      .def_property_readonly("closed", &MeshReport::closed)
      .def_property_readonly("usable", &MeshReport::usable,
                             "True when no issue is an error: spheres can be generated")
      .def_property_readonly("geometry_repaired", &MeshReport::geometry_repaired,
                             "True when validation changed the solid (a weld within a "
                             "tolerance or across cracks, triangles the weld removed, holes "
                             "filled, a wrap): results and certificates hold for the repaired "
                             "mesh only")
      .def_property_readonly("repairs", &MeshReport::repairs,
                             "those repairs in one line, or '' when there were none")
      .def_property_readonly("first_error", &MeshReport::first_error,
                             "the first error as one line, or '' when usable")
      .def("__repr__", &ReportRepr);

  py::class_<Mesh, std::shared_ptr<Mesh>>(
      m, "Mesh",
      "A triangle mesh: vertices (V, 3) float64 in the mesh's own units and frame, triangles "
      "(T, 3) int32, 0-based, counter-clockwise seen from outside. Every call taking a mesh "
      "also takes a path, a (vertices, faces) pair or an object with .vertices and .faces "
      "(trimesh.Trimesh), converted as Mesh(vertices, triangles) converts.")
      .def(py::init(&MeshFromArrays), py::arg("vertices"), py::arg("triangles"),
           "Mesh(vertices, triangles): vertices a (V, 3) array of any float dtype (float64, "
           "float32, ...), triangles a (T, 3) array of any integer dtype (int32, int64, uint32, "
           "...), in any layout, or Python sequences; converted once to float64 and int32 and "
           "copied into the mesh. TypeError for another dtype, ValueError for another shape or "
           "an index int32 cannot hold. Nothing is validated here: see validate() and "
           "prepare().")
      .def_property_readonly(
          "vertices", [](py::object self) { return VerticesView(self.cast<const Mesh&>(), self); },
          "(V, 3) float64, read-only view (no copy), mesh units")
      .def_property_readonly(
          "triangles",
          [](py::object self) { return TrianglesView(self.cast<const Mesh&>(), self); },
          "(T, 3) int32, read-only view (no copy)")
      .def_property_readonly(
          "faces", [](py::object self) { return TrianglesView(self.cast<const Mesh&>(), self); },
          "the triangles under trimesh's name: (T, 3) int32, read-only view (no copy)")
      .def_property_readonly("num_vertices", &Mesh::num_vertices)
      .def_property_readonly("num_triangles", &Mesh::num_triangles)
      .def_property_readonly(
          "sha256", [](const Mesh& mesh) { return FormatSha256(MeshSha256(mesh)); },
          "'sha256:<64 hex>' content hash of the mesh as it is (the service keys meshes by "
          "the hash of the validated, re-oriented mesh: see Solid.sha256)")
      .def(
          "validate",
          [](const Mesh& mesh, bool check_self_intersections, const RepairOptions& repair,
             bool fill_holes, double weld_tolerance) {
            ValidateOptions options;
            options.check_self_intersections = check_self_intersections;
            options.repair = RepairArgument(repair, fill_holes, weld_tolerance);
            py::gil_scoped_release release;
            return ValidateMesh(mesh, options).report;
          },
          py::kw_only(), py::arg("check_self_intersections") = true,
          py::arg("repair") = RepairOptions{}, py::arg("fill_holes") = false,
          py::arg("weld_tolerance") = 0.0,
          "The validation report (MeshReport) of this mesh after the repair asked for (an "
          "inscribe.Repair or a level name; fill_holes=True is 'fill'); never raises for a bad "
          "mesh. Coincident vertices are welded first (within weld_tolerance, mesh units; 0: "
          "identical positions only). Cost O(T log T + V log V), more with 'wrap'.")
      .def(
          "repaired",
          [](const Mesh& mesh, const RepairOptions& repair, bool check_self_intersections) {
            ValidateOptions options;
            options.check_self_intersections = check_self_intersections;
            options.repair = repair;
            ValidatedMesh validated;
            {
              py::gil_scoped_release release;
              validated = ValidateMesh(mesh, options);
            }
            return py::make_tuple(std::make_shared<Mesh>(std::move(validated.mesh)),
                                  validated.report);
          },
          py::arg("repair") = RepairOptions{}, py::kw_only(),
          py::arg("check_self_intersections") = true,
          "(mesh, report): the mesh as validation returns it after the repair asked for "
          "(welded, oriented, repaired; the wrap when it wrapped), and its MeshReport. The mesh "
          "is the input when the report is not usable.")
      .def("__repr__", [](const Mesh& mesh) {
        return absl::StrCat("Mesh(vertices=", mesh.num_vertices(),
                            ", triangles=", mesh.num_triangles(), ")");
      });

  m.def(
      "load_mesh", [](py::handle path) { return LoadMesh(PathOf(path, "path")); }, py::arg("path"),
      "Reads an OFF, OBJ, STL, PLY, COLLADA (.dae) or glTF (.gltf, .glb) file (by extension) "
      "(a str or os.PathLike) into a Mesh, polygons triangulated (COLLADA and glTF: every node's "
      "mesh placed by its "
      "transform, in metres, in the file's own axes). "
      "FileNotFoundError for a missing file, ValueError for a malformed one. Not validated.");

  m.def(
      "write_mesh",
      [](py::handle mesh_like, py::handle path_like) {
        const std::shared_ptr<Mesh> mesh = MeshOf(mesh_like);
        const std::string path = PathOf(path_like, "path");
        absl::Status status;
        {
          py::gil_scoped_release release;
          status = WriteMesh(path, *mesh);
        }
        OkOrRaise(status);
      },
      py::arg("mesh"), py::arg("path"),
      "Writes `mesh` (anything a mesh argument takes) to `path` as OFF, OBJ, PLY or STL (by "
      "extension) with 17 significant digits, so "
      "load_mesh reads back the same doubles; atomically. ValueError for another extension.");

  m.def(
      "_mesh_of", [](py::handle mesh) { return MeshOf(mesh); }, py::arg("mesh"),
      "The inscribe.Mesh of anything a mesh argument takes (inscribe.Client's uploads).");

  py::class_<Solid, std::shared_ptr<Solid>>(
      m, "Solid",
      "A validated closed mesh with its boundary oracle, ready for generation, evaluation and "
      "certification. Make one with inscribe.prepare(mesh) and reuse it: generate(mesh) "
      "prepares one on every call.")
      .def_property_readonly("report", [](const Solid& s) { return s.report; })
      .def_property_readonly(
          "sha256", [](const Solid& s) { return s.sha256; },
          "'sha256:<64 hex>' of the validated mesh: the service's mesh key")
      .def_property_readonly(
          "mesh", [](const Solid& s) { return std::make_shared<Mesh>(s.mesh()); },
          "the validated mesh (orientation fixed), a copy")
      .def("__repr__", [](const Solid& s) {
        return absl::StrCat("Solid(", s.sha256.substr(0, 23),
                            "..., triangles=", s.mesh().num_triangles(), ")");
      });

  m.def(
      "prepare",
      [](py::handle mesh, const RepairOptions& repair, bool fill_holes,
         bool check_self_intersections) {
        return PrepareSolidReleasingGil(*MeshOf(mesh), RepairArgument(repair, fill_holes, 0.0),
                                        check_self_intersections);
      },
      py::arg("mesh"), py::kw_only(), py::arg("repair") = RepairOptions{},
      py::arg("fill_holes") = false, py::arg("check_self_intersections") = true,
      "Validates `mesh` (an inscribe.Mesh, a path, a (vertices, faces) pair or a trimesh; "
      "repaired as `repair` allows: an inscribe.Repair or a level name, "
      "default 'safe'; fill_holes=True is 'fill'; every change is warned about as "
      "inscribe.MeshWarning) and builds its "
      "boundary oracle. inscribe.Error with code FAILED_PRECONDITION naming the first problem "
      "('mesh is not closed: 6 border edges') when it does not bound a usable solid. Cost "
      "O(T log T).");
}

}  // namespace inscribe::python
