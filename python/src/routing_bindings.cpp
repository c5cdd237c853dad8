// The service's routing and addressing rules, for inscribe.Client: written once in wire/
// (keys.cpp, service_address.cpp).
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "inscribe/wire/keys.h"
#include "inscribe/wire/service_address.h"

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
  m.def(
      "_target_with_default_port",
      [](const std::string& target) { return wire::TargetWithDefaultPort(target); },
      py::arg("target"),
      "`target` as gRPC should dial it: HOST alone gets inscribed's default port "
      "(wire::TargetWithDefaultPort).");
}

}  // namespace inscribe::python
