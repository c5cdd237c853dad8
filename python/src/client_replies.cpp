// What inscribe.Client receives: every answer of the service, read by wire's *FromProto
// functions (the conversions the C++ client uses) into the objects the in-process API returns
// (SphereSet, QualityReport, CoverCertificate, MeshReport, Hierarchy, DeformationErrorBounds)
// and numpy arrays. An answer wire refuses is the server's fault (a bug or a version
// mismatch): inscribe.Error INTERNAL "malformed <RPC> response: <why>", as from the C++ client.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "bindings.h"
#include "client_messages.h"
#include "deformation_results.h"
#include "distance_types.h"
#include "inscribe/wire/cache_stats.h"
#include "inscribe/wire/convert.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

[[noreturn]] void Malformed(const char* rpc, absl::string_view problem) {
  RaiseStatus(absl::InternalError(absl::StrCat("malformed ", rpc, " response: ", problem)));
}

template <typename T>
T ValueOrMalformed(absl::StatusOr<T> value, const char* rpc) {
  if (!value.ok()) Malformed(rpc, value.status().message());
  return *std::move(value);
}

// The `Message` in `data`, parsed without the GIL.
template <typename Message>
Message Parsed(const py::bytes& data, const char* rpc) {
  char* buffer = nullptr;
  Py_ssize_t length = 0;
  if (PyBytes_AsStringAndSize(data.ptr(), &buffer, &length) != 0) throw py::error_already_set();
  Message message;
  bool parsed = false;
  {
    py::gil_scoped_release release;
    parsed = message.ParseFromArray(buffer, static_cast<int>(length));
  }
  if (!parsed) {
    Malformed(rpc, absl::StrCat("not a ", std::string(Message::descriptor()->name())));
  }
  return message;
}

// The fields of inscribe.DistanceReply: the answers as arrays, and with `certified` (the
// request named covers) the intervals and closer-than answers.
py::dict DistanceReplyFields(const v1::DistanceResults& answers, bool certified, double seconds,
                             const char* rpc) {
  const std::vector<DistanceResult> results =
      ValueOrMalformed(wire::DistanceResultsFromProto(answers), rpc);
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<double> distance(n), point_a({n, py::ssize_t{3}}), point_b({n, py::ssize_t{3}});
  py::array_t<std::int32_t> sphere_a(n), sphere_b(n);
  py::array_t<bool> closer(n);
  {
    auto d = distance.mutable_unchecked<1>();
    auto pa = point_a.mutable_unchecked<2>();
    auto pb = point_b.mutable_unchecked<2>();
    auto sa = sphere_a.mutable_unchecked<1>();
    auto sb = sphere_b.mutable_unchecked<1>();
    auto c = closer.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < n; ++i) {
      const DistanceResult& r = results[static_cast<std::size_t>(i)];
      d(i) = r.distance;
      sa(i) = r.sphere_a;
      sb(i) = r.sphere_b;
      c(i) = r.closer;
      for (int k = 0; k < 3; ++k) {
        pa(i, k) = r.point_a[k];
        pb(i, k) = r.point_b[k];
      }
    }
  }
  std::vector<double> lower, upper;
  py::list closer_answers;
  if (certified) {
    for (const CertifiedDistanceResult& r :
         ValueOrMalformed(wire::CertifiedDistanceResultsFromProto(answers), rpc)) {
      lower.push_back(r.lower);
      upper.push_back(r.upper);
      closer_answers.append(CloserAnswerName(r.closer));
    }
  }
  py::dict fields;
  fields["distance"] = distance;
  fields["sphere_a"] = sphere_a;
  fields["sphere_b"] = sphere_b;
  fields["point_a"] = point_a;
  fields["point_b"] = point_b;
  fields["closer"] = closer;
  fields["lower"] = py::array_t<double>(static_cast<py::ssize_t>(lower.size()), lower.data());
  fields["upper"] = py::array_t<double>(static_cast<py::ssize_t>(upper.size()), upper.data());
  fields["answers"] = closer_answers;
  fields["server_seconds"] = seconds;
  return fields;
}

}  // namespace

std::tuple<py::object, py::object> GenerateCall::Read(const py::bytes& data) const {
  const auto message = Parsed<v1::GenerateResponse>(data, "Generate");
  if (message.has_progress()) return {py::float_(message.progress().fraction()), py::none()};
  if (!message.has_result()) return {py::none(), py::none()};
  const v1::GenerateResult& result = message.result();
  GeneratedSphereSet generated =
      ValueOrMalformed(wire::GeneratedSphereSetFromProto(result), "Generate");
  std::optional<CoverCertificate> certificate;
  if (generated.cover) certificate = generated.cover->certificate;
  auto spheres = std::make_shared<PySphereSet>();
  spheres->kind = SphereSetKindName(generated.kind);
  spheres->mesh_sha256 = result.mesh_sha256();
  spheres->quality = generated.quality;
  spheres->certificate = certificate;
  spheres->set = std::move(generated.set);
  py::dict fields;
  fields["spheres"] = spheres;
  fields["sphere_set_key"] = result.sphere_set_key();
  fields["mesh_sha256"] = result.mesh_sha256();
  fields["cache"] = result.cache();
  fields["voxel_size"] = generated.voxel_size;
  fields["seconds"] = generated.seconds;
  fields["quality"] = generated.quality;
  fields["certificate"] = certificate;
  fields["selection"] = SphereSelectionName(generated.selection);
  fields["pool_size"] = generated.pool_size;
  return {py::none(), std::move(fields)};
}

void BindClientReplies(py::module_& m) {
  m.def(
      "_inspect_mesh_reply",
      [](const py::bytes& data) {
        auto response = Parsed<v1::InspectMeshResponse>(data, "InspectMesh");
        py::dict fields;
        fields["mesh_sha256"] = response.mesh_sha256();
        fields["report"] =
            ValueOrMalformed(wire::MeshReportFromProto(response.report()), "InspectMesh");
        return fields;
      },
      py::arg("data"), "The fields of inscribe.InspectMeshResult.");

  m.def(
      "_put_mesh_reply",
      [](const py::bytes& data) {
        return Parsed<v1::PutMeshResponse>(data, "PutMesh").mesh_sha256();
      },
      py::arg("data"), "The stored mesh's key.");

  m.def(
      "_put_sphere_set_reply",
      [](const py::bytes& data) {
        return Parsed<v1::PutSphereSetResponse>(data, "PutSphereSet").sphere_set_key();
      },
      py::arg("data"), "The stored set's key.");

  m.def(
      "_sphere_set_reply",
      [](const py::bytes& data) {
        const auto response = Parsed<v1::GetSphereSetResponse>(data, "GetSphereSet");
        auto set = std::make_shared<PySphereSet>();
        set->set = ValueOrMalformed(wire::SphereSetFromProto(response.spheres()), "GetSphereSet");
        set->mesh_sha256 = response.mesh_sha256();
        return set;
      },
      py::arg("data"), "The SphereSet, its contacts and mesh_sha256 when it has them.");

  m.def(
      "_hierarchy_reply",
      [](const py::bytes& data, const std::string& volume) {
        const HierarchyVolume asked = VolumeOf(volume);
        const auto response = Parsed<v1::GetHierarchyResponse>(data, "GetHierarchy");
        absl::StatusOr<SphereHierarchy> hierarchy;
        {
          py::gil_scoped_release release;
          hierarchy = SphereHierarchy::Deserialize(response.hierarchy());
        }
        if (!hierarchy.ok()) {
          Malformed("GetHierarchy", absl::StrCat("hierarchy: ", hierarchy.status().message()));
        }
        if (hierarchy->volume() != asked) {
          Malformed("GetHierarchy",
                    absl::StrCat("hierarchy: asked for ", HierarchyVolumeName(asked), ", got ",
                                 HierarchyVolumeName(hierarchy->volume())));
        }
        return std::make_shared<SphereHierarchy>(*std::move(hierarchy));
      },
      py::arg("data"), py::kw_only(), py::arg("volume"),
      "The Hierarchy, checked as it is read (Hierarchy.deserialize), of the volume asked for.");

  m.def(
      "_update_deformation_reply",
      [](const py::bytes& data, bool bounds) {
        const auto response = Parsed<v1::UpdateDeformationResponse>(data, "UpdateDeformation");
        py::dict fields;
        fields["spheres"] = DeformedSphereSet(
            ValueOrMalformed(wire::DeformedSpheresFromProto(response), "UpdateDeformation"));
        // The wire has no presence bit for the bounds: they are there when they were asked for.
        fields["bounds"] =
            bounds ? py::cast(wire::DeformationBoundsFromProto(response)) : py::none();
        fields["reference_spheres"] = response.reference_spheres();
        fields["deformed_mesh_sha256"] = response.deformed_mesh_sha256();
        fields["sphere_set_key"] = response.sphere_set_key();
        return fields;
      },
      py::arg("data"), py::kw_only(), py::arg("bounds"),
      "The fields of inscribe.DeformationResult (bounds: whether they were asked for).");

  m.def(
      "_distance_reply",
      [](const py::bytes& data, bool certified) {
        const auto response = Parsed<v1::DistanceResponse>(data, "Distance");
        return DistanceReplyFields(response.results(), certified, response.seconds(), "Distance");
      },
      py::arg("data"), py::kw_only(), py::arg("certified"),
      "The fields of inscribe.DistanceReply (certified: the request named covers).");

  m.def(
      "_distance_frame_reply",
      [](const py::bytes& data, bool certified) {
        const auto reply = Parsed<v1::DistanceFrameResult>(data, "DistanceStream");
        return std::make_tuple(
            reply.frame(), DistanceReplyFields(reply.results(), certified, 0.0, "DistanceStream"));
      },
      py::arg("data"), py::kw_only(), py::arg("certified"),
      "(the frame number it answers, the fields of inscribe.DistanceReply).");

  m.def(
      "_evaluate_reply",
      [](const py::bytes& data) {
        const auto response = Parsed<v1::EvaluateResponse>(data, "Evaluate");
        if (!response.has_quality()) Malformed("Evaluate", "no quality report");
        return wire::QualityReportFromProto(response.quality());
      },
      py::arg("data"), "The QualityReport.");

  m.def(
      "_certify_cover_reply",
      [](const py::bytes& data) {
        const auto response = Parsed<v1::CertifyCoverResponse>(data, "CertifyCover");
        if (!response.has_certificate()) Malformed("CertifyCover", "no certificate");
        return ValueOrMalformed(wire::CoverCertificateFromProto(response.certificate()),
                                "CertifyCover");
      },
      py::arg("data"), "The CoverCertificate (its failed cells are not sent, only counted).");

  m.def(
      "_cache_stats_reply",
      [](const py::bytes& data) {
        const wire::CacheStats stats =
            wire::CacheStatsFromProto(Parsed<v1::CacheStatsResponse>(data, "CacheStats"));
        py::dict counters;
        for (const wire::CacheStatsCounter& counter : wire::kCacheStatsCounters) {
          counters[counter.name] = stats.*counter.value;
        }
        return counters;
      },
      py::arg("data"), "Every counter of wire::kCacheStatsCounters, by its name.");
}

}  // namespace inscribe::python
