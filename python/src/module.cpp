// The _inscribe extension module: core and robot bound for Python, and the service's messages
// for inscribe.Client, built and read by wire/. The package `inscribe`
// (python/inscribe/__init__.py) re-exports it with the service client.
#include <pybind11/pybind11.h>

#include "bindings.h"

PYBIND11_MODULE(_inscribe, m) {
  m.doc() = "inscribe's core (meshes, sphere sets, distance, deformation) and robot functions";
  inscribe::python::BindMesh(m);
  inscribe::python::BindSpheres(m);
  inscribe::python::BindGeneration(m);
  inscribe::python::BindDistance(m);
  inscribe::python::BindDeformation(m);
  inscribe::python::BindRobot(m);
  inscribe::python::BindRouting(m);
  inscribe::python::BindScene(m);
  inscribe::python::BindClientRequests(m);
  inscribe::python::BindClientReplies(m);
}
