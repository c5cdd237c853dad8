// The messages of inscribe.Client, built and read here with wire's conversions
// (client_requests.cpp, client_replies.cpp): python/inscribe/_client.py carries their bytes.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <tuple>

#include "generation_arguments.h"
#include "google/protobuf/message.h"
#include "inscribe/v1/service.pb.h"

namespace inscribe::python {

namespace py = pybind11;

// `message` serialised (the GIL released: a mesh can be large).
py::bytes Serialized(const google::protobuf::Message& message);

// One Generate call's settings, checked (SphereSetParametersOf) and converted
// (wire::GenerateRequestToProto) once, before anything is sent.
class GenerateCall {
 public:
  GenerateCall(const GenerateArguments& arguments, MeshRepair repair, double progress_interval);

  // The request for the mesh stored as `mesh_sha256`.
  py::bytes RequestFor(const std::string& mesh_sha256) const;

  // One GenerateResponse of the stream: (fraction, None) for progress, (None, the fields of
  // inscribe.GenerateResult as a dict) for the result, (None, None) for an empty message.
  // inscribe.Error INTERNAL for a malformed one.
  std::tuple<py::object, py::object> Read(const py::bytes& message) const;

 private:
  v1::GenerateRequest request_;
};

// The frames of one DistanceStream: its volume and tolerance, checked and converted once.
class DistanceFrames {
 public:
  // ValueError for a volume other than "sphere" or "rss".
  DistanceFrames(const std::string& volume, double abs_err, double rel_err);

  // Frame `number` of `pairs`, each (key_a, key_b, pose_a, pose_b[, cover_a, cover_b]) with
  // (7,) float64 poses (normalised; ValueError naming the pair otherwise), and whether the
  // frame is certified (its pairs name covers).
  std::tuple<py::bytes, bool> Frame(std::int64_t number, const py::sequence& pairs) const;

 private:
  v1::HierarchyVolume volume_;
  v1::DistanceTolerance tolerance_;
};

}  // namespace inscribe::python
