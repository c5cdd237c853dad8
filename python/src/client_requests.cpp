// What inscribe.Client sends: every request of the service, built from the Python-side inputs
// by wire's *ToProto functions (the conversions the C++ client and the server use) and
// serialised, so that python/inscribe/_client.py only carries bytes. Also the service's method
// table, read from the proto's descriptor.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "client_messages.h"
#include "deformation_results.h"
#include "distance_types.h"
#include "generation_arguments.h"
#include "google/protobuf/descriptor.h"
#include "inscribe/wire/convert.h"
#include "inscribe/wire/keys.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

// The set of an inscribe.SphereSet, its contacts included, or of an (N, 4) float64 array.
SphereSet SphereSetOf(py::handle spheres) {
  if (py::isinstance<PySphereSet>(spheres)) return spheres.cast<const PySphereSet&>().set;
  SphereSet set;
  set.spheres = SpheresOf(spheres);
  return set;
}

// One (7,) pose, normalised; ValueError naming `name` otherwise.
RigidPose OnePoseOf(py::handle value, const std::string& name) {
  const std::vector<RigidPose> poses = PosesOf(value, name.c_str());
  if (poses.size() != 1) {
    throw py::value_error(
        absl::StrCat(name, " must be one pose of 7 numbers, got ", poses.size(), " poses"));
  }
  return poses.front();
}

// (name, "/inscribe.v1.Inscribe/<name>", client streaming, server streaming) of every RPC.
std::vector<std::tuple<std::string, std::string, bool, bool>> RpcMethods() {
  const google::protobuf::ServiceDescriptor* service =
      v1::PutMeshRequest::descriptor()->file()->FindServiceByName("Inscribe");
  std::vector<std::tuple<std::string, std::string, bool, bool>> methods;
  for (int i = 0; i < service->method_count(); ++i) {
    const google::protobuf::MethodDescriptor* method = service->method(i);
    const std::string name(method->name());
    methods.emplace_back(name, absl::StrCat("/", std::string(service->full_name()), "/", name),
                         method->client_streaming(), method->server_streaming());
  }
  return methods;
}

}  // namespace

GenerateCall::GenerateCall(const GenerateArguments& arguments, MeshRepair repair,
                           double progress_interval) {
  wire::GenerateRequestToProto("", SphereSetParametersOf(arguments), repair, &request_);
  request_.set_progress_interval(progress_interval);
}

py::bytes GenerateCall::RequestFor(const std::string& mesh_sha256) const {
  v1::GenerateRequest request = request_;
  request.set_mesh_sha256(mesh_sha256);
  return Serialized(request);
}

DistanceFrames::DistanceFrames(const std::string& volume, double abs_err, double rel_err)
    : volume_(wire::VolumeToProto(VolumeOf(volume))) {
  DistanceRequest tolerance;
  tolerance.abs_err = abs_err;
  tolerance.rel_err = rel_err;
  wire::ToleranceToProto(tolerance, &tolerance_);
}

std::tuple<py::bytes, bool> DistanceFrames::Frame(std::int64_t number,
                                                  const py::sequence& pairs) const {
  v1::DistanceFrame frame;
  frame.set_frame(number);
  frame.set_volume(volume_);
  *frame.mutable_tolerance() = tolerance_;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::string at = absl::StrCat("pairs[", i, "]");
    const py::sequence pair = pairs[i].cast<py::sequence>();
    if (pair.size() != 4 && pair.size() != 6) {
      throw py::value_error(absl::StrCat(at,
                                         " must be (key_a, key_b, pose_a, pose_b[, cover_a, "
                                         "cover_b]), got ",
                                         pair.size(), " items"));
    }
    v1::DistancePair* out = frame.add_pairs();
    out->set_sphere_set_a(pair[0].cast<std::string>());
    out->set_sphere_set_b(pair[1].cast<std::string>());
    wire::PoseToProto(OnePoseOf(pair[2], at + " pose_a"), out->mutable_pose_a());
    wire::PoseToProto(OnePoseOf(pair[3], at + " pose_b"), out->mutable_pose_b());
    if (pair.size() == 6) {
      out->set_cover_a(pair[4].cast<std::string>());
      out->set_cover_b(pair[5].cast<std::string>());
    }
  }
  const bool certified = frame.pairs_size() > 0 && !frame.pairs(0).cover_a().empty();
  return {Serialized(frame), certified};
}

py::bytes Serialized(const google::protobuf::Message& message) {
  std::string bytes;
  {
    py::gil_scoped_release release;
    message.SerializeToString(&bytes);
  }
  return py::bytes(bytes);
}

void BindClientRequests(py::module_& m) {
  m.def("_rpc_methods", &RpcMethods,
        "(name, path, client streaming, server streaming) of every RPC of inscribe.v1.Inscribe.");

  m.def(
      "_inspect_mesh_request",
      [](const Mesh& mesh, bool skip_self_intersections, const RepairOptions& repair) {
        v1::InspectMeshRequest request;
        wire::MeshToProto(mesh, request.mutable_mesh());
        request.set_skip_self_intersections(skip_self_intersections);
        wire::RepairOptionsToProto(repair, &request);
        return Serialized(request);
      },
      py::arg("mesh"), py::kw_only(), py::arg("skip_self_intersections"), py::arg("repair"));

  m.def("_repair_argument", &RepairArgument, py::arg("repair"), py::kw_only(),
        py::arg("fill_holes"), py::arg("weld_tolerance"),
        "The Repair a call asks for, with the older fill_holes and weld_tolerance folded in.");

  m.def(
      "_put_mesh_request",
      [](const Mesh& mesh, const RepairOptions& repair) {
        v1::PutMeshRequest request;
        wire::MeshToProto(mesh, request.mutable_mesh());
        wire::RepairOptionsToProto(repair, &request);
        return Serialized(request);
      },
      py::arg("mesh"), py::kw_only(), py::arg("repair"));

  py::class_<GenerateCall>(m, "_GenerateCall",
                           "A Generate call's settings, checked and converted once: its request "
                           "for a mesh key, and its answers read.")
      .def(
          py::init([](std::optional<std::int64_t> max_spheres, std::optional<double> voxel_size,
                      const std::string& kind, std::optional<double> object_angle,
                      std::optional<double> epsilon, std::optional<int> samples,
                      std::optional<bool> subdivide_boundary,
                      std::optional<std::int64_t> max_voxels, std::optional<double> dilation_growth,
                      std::optional<double> max_protrusion, std::optional<double> cover_resolution,
                      bool evaluate, std::optional<std::int64_t> quality_samples,
                      const std::optional<std::string>& selection, const RepairOptions& repair,
                      double progress_interval) {
            return GenerateCall({max_spheres, voxel_size, kind, object_angle, epsilon, samples,
                                 subdivide_boundary, max_voxels, dilation_growth, max_protrusion,
                                 cover_resolution, evaluate, quality_samples, selection},
                                repair.level, progress_interval);
          }),
          py::kw_only(), py::arg("max_spheres"), py::arg("voxel_size"), py::arg("kind"),
          py::arg("object_angle"), py::arg("epsilon"), py::arg("samples"),
          py::arg("subdivide_boundary"), py::arg("max_voxels"), py::arg("dilation_growth"),
          py::arg("max_protrusion"), py::arg("cover_resolution"), py::arg("evaluate"),
          py::arg("quality_samples"), py::arg("selection"), py::arg("repair"),
          py::arg("progress_interval"))
      .def("request", &GenerateCall::RequestFor, py::arg("mesh_sha256"))
      .def("read", &GenerateCall::Read, py::arg("message"),
           "One message of the Generate stream: (fraction, None) for progress, (None, the "
           "GenerateResult's fields) for the result, (None, None) for neither.");

  m.def(
      "_put_sphere_set_request",
      [](py::handle spheres, const std::string& mesh_sha256,
         const std::optional<CoverCertificate>& certificate) {
        v1::PutSphereSetRequest request;
        wire::SphereSetToProto(SphereSetOf(spheres), request.mutable_spheres());
        request.set_mesh_sha256(mesh_sha256);
        if (certificate) wire::CoverCertificateToProto(*certificate, request.mutable_certificate());
        return std::make_tuple(Serialized(request),
                               wire::ContentRouteKey(request.spheres().SerializeAsString()));
      },
      py::arg("spheres"), py::kw_only(), py::arg("mesh_sha256") = "",
      py::arg("certificate") = py::none(),
      "(request, the route key of the set's content, for a set without a mesh).");

  m.def(
      "_get_sphere_set_request",
      [](const std::string& sphere_set_key) {
        v1::GetSphereSetRequest request;
        request.set_sphere_set_key(sphere_set_key);
        return Serialized(request);
      },
      py::arg("sphere_set_key"));

  m.def(
      "_get_hierarchy_request",
      [](const std::string& sphere_set_key, const std::string& volume) {
        v1::GetHierarchyRequest request;
        request.set_sphere_set_key(sphere_set_key);
        request.set_volume(wire::VolumeToProto(VolumeOf(volume)));
        return Serialized(request);
      },
      py::arg("sphere_set_key"), py::kw_only(), py::arg("volume"));

  m.def(
      "_update_deformation_request",
      [](const std::string& sphere_set_key, py::handle vertices, const std::string& mesh_sha256,
         std::optional<double> xi, bool strict, bool interpolated_normal, bool bounds, bool store) {
        const py::array_t<double> v = RequireMatrix<double>(vertices, 3, "vertices");
        v1::UpdateDeformationRequest request;
        request.set_mesh_sha256(mesh_sha256);
        request.set_sphere_set_key(sphere_set_key);
        // Row-major (V, 3): the storage is already the wire's x0, y0, z0, x1, ...
        request.mutable_vertices()->Add(v.data(), v.data() + v.size());
        wire::DeformationSettings settings;
        settings.options = DeformationOptionsOf(xi, strict, interpolated_normal);
        settings.bounds = bounds;
        settings.store = store;
        wire::DeformationSettingsToProto(settings, &request);
        return Serialized(request);
      },
      py::arg("sphere_set_key"), py::arg("vertices"), py::kw_only(), py::arg("mesh_sha256"),
      py::arg("xi"), py::arg("strict"), py::arg("interpolated_normal"), py::arg("bounds"),
      py::arg("store"));

  m.def(
      "_distance_request",
      [](const std::string& sphere_set_a, const std::string& sphere_set_b, py::handle poses_b,
         py::handle poses_a, const std::string& volume, double abs_err, double rel_err,
         std::optional<double> closer_than, bool brute_force, const std::string& cover_a,
         const std::string& cover_b) {
        v1::DistanceRequest request;
        request.set_sphere_set_a(sphere_set_a);
        request.set_sphere_set_b(sphere_set_b);
        request.set_volume(wire::VolumeToProto(VolumeOf(volume)));
        wire::PosesToProto(
            poses_a.is_none() ? std::vector<RigidPose>{RigidPose{}} : PosesOf(poses_a, "poses_a"),
            request.mutable_poses_a());
        wire::PosesToProto(PosesOf(poses_b, "poses_b"), request.mutable_poses_b());
        DistanceRequest tolerance;
        tolerance.abs_err = abs_err;
        tolerance.rel_err = rel_err;
        if (closer_than) tolerance.closer_than = *closer_than;
        wire::ToleranceToProto(tolerance, request.mutable_tolerance());
        request.set_brute_force(brute_force);
        request.set_cover_a(cover_a);
        request.set_cover_b(cover_b);
        return Serialized(request);
      },
      py::arg("sphere_set_a"), py::arg("sphere_set_b"), py::arg("poses_b"), py::kw_only(),
      py::arg("poses_a"), py::arg("volume"), py::arg("abs_err"), py::arg("rel_err"),
      py::arg("closer_than"), py::arg("brute_force"), py::arg("cover_a"), py::arg("cover_b"));

  py::class_<DistanceFrames>(m, "_DistanceFrames",
                             "The frames of one DistanceStream: its volume and tolerance, "
                             "checked once, and each frame's pairs.")
      .def(py::init<const std::string&, double, double>(), py::arg("volume"), py::arg("abs_err"),
           py::arg("rel_err"))
      .def("frame", &DistanceFrames::Frame, py::arg("number"), py::arg("pairs"),
           "(frame message, whether its pairs name covers); pairs of (key_a, key_b, pose_a, "
           "pose_b[, cover_a, cover_b]), poses (7,) float64.");

  m.def(
      "_evaluate_request",
      [](const std::string& mesh_sha256, const std::string& sphere_set_key) {
        v1::EvaluateRequest request;
        request.set_mesh_sha256(mesh_sha256);
        request.set_sphere_set_key(sphere_set_key);
        wire::QualityOptionsToProto(QualityOptions{}, &request);
        return Serialized(request);
      },
      py::arg("mesh_sha256"), py::arg("sphere_set_key"));

  m.def(
      "_certify_cover_request",
      [](const std::string& mesh_sha256, py::handle spheres, std::optional<double> resolution) {
        CoverCertifyOptions options;
        Override(options.resolution, resolution);
        OkOrRaise(CheckCoverCertifyOptions(options));
        v1::CertifyCoverRequest request;
        request.set_mesh_sha256(mesh_sha256);
        if (py::isinstance<py::str>(spheres)) {
          request.set_sphere_set_key(spheres.cast<std::string>());
        } else {
          wire::SphereSetToProto(SphereSetOf(spheres), request.mutable_sphere_set());
        }
        request.set_resolution(options.resolution);
        return Serialized(request);
      },
      py::arg("mesh_sha256"), py::arg("spheres"), py::kw_only(), py::arg("resolution"),
      "spheres: a cached set's key, a SphereSet or an (N, 4) float64 array.");

  m.def("_cache_stats_request", [] { return Serialized(v1::CacheStatsRequest()); });
}

}  // namespace inscribe::python
