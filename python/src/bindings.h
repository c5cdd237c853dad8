// The parts of the _inscribe extension module, one function per group of bindings, and what
// they share.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/solid.h"

namespace inscribe::python {

namespace py = pybind11;

void BindMesh(py::module_& m);
void BindSpheres(py::module_& m);
void BindGeneration(py::module_& m);
void BindDistance(py::module_& m);
void BindDeformation(py::module_& m);
void BindRobot(py::module_& m);
void BindRouting(py::module_& m);
void BindScene(py::module_& m);
void BindClientRequests(py::module_& m);
void BindClientReplies(py::module_& m);

// warnings.warn(inscribe.MeshWarning) for each of report.notices(), and once more when the
// geometry was repaired (results hold for the mesh `sha256` only). Needs the GIL.
void WarnAboutMesh(const MeshReport& report, const std::string& sha256);

// The repair a Python call asks for: `repair` (an inscribe.Repair, or its level's name, which
// converts implicitly) with the older keywords folded in: fill_holes=True is level "fill"
// (ValueError beside another level than "safe" or "fill"), a weld_tolerance > 0 sets the weld
// (ValueError beside a different one in `repair`).
RepairOptions RepairArgument(RepairOptions repair, bool fill_holes, double weld_tolerance);

// PrepareSolid without the GIL; raises as RaiseStatus; warns as WarnAboutMesh.
std::shared_ptr<Solid> PrepareSolidReleasingGil(const Mesh& mesh, const RepairOptions& repair,
                                                bool check_self_intersections);

// The mesh of any argument that takes one: an inscribe.Mesh as it is; a path (str or
// os.PathLike) read as load_mesh reads it; a (vertices, faces) tuple or list of two arrays, or
// an object with .vertices and .faces (trimesh.Trimesh), converted as Mesh(vertices, triangles)
// converts. TypeError naming what was given for anything else.
std::shared_ptr<Mesh> MeshOf(py::handle mesh);

// A path argument (str or os.PathLike) as a string; TypeError naming `name` otherwise.
std::string PathOf(py::handle path, const char* name);

// An inscribe.Solid as given, or one prepared (default validation) from anything MeshOf takes.
std::shared_ptr<Solid> SolidOf(py::handle mesh_or_solid);

}  // namespace inscribe::python
