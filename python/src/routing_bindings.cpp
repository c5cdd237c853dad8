// The service's routing rules, for inscribe.Client: written once in wire/src/keys.cpp.
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "inscribe/wire/keys.h"

namespace inscribe::python {

void BindRouting(py::module_& m) {
  m.def(
      "_route_key", [](const std::string& key) { return wire::RouteKey(key); }, py::arg("key"),
      "What routes a mesh or sphere-set key between replicas (wire::RouteKey).");
  m.def(
      "_rendezvous_order",
      [](const std::string& route_key, const std::vector<std::string>& names) {
        return wire::RendezvousOrder(route_key, names);
      },
      py::arg("route_key"), py::arg("names"),
      "Replica indices for `route_key`, best first (wire::RendezvousOrder).");
}

}  // namespace inscribe::python
