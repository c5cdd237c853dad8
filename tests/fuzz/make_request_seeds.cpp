// Writes the seed corpus of fuzz_requests: valid requests (and a few near misses) of every
// kind, naming the fuzzing server's stored cube and sphere sets, each sent once to check what
// it gets. Run by hand when the protocol changes:
//   build/tests/fuzz/make_request_seeds tests/fuzz/corpus/requests
// The keys are content hashes, so the same program writes the same bytes on any machine.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/convert.h"
#include "request_fuzz_server.h"

namespace {

using inscribe::fuzz::RequestKind;
namespace v1 = inscribe::v1;

int written = 0;

void Seed(const std::string& dir, RequestKind kind, const google::protobuf::Message& request,
          const std::string& tag) {
  std::string bytes(1, static_cast<char>(kind));
  bytes += request.SerializeAsString();
  const std::string path = dir + "/" + inscribe::fuzz::RequestKindName(kind) + "-" + tag;
  std::ofstream(path, std::ios::binary) << bytes;
  const std::optional<grpc::Status> status = inscribe::fuzz::SendRequest(
      inscribe::fuzz::TheFuzzServer(), kind, absl::string_view(bytes).substr(1));
  std::printf("%-40s %5zu bytes  %s %s\n", path.c_str(), bytes.size(),
              status && status->ok() ? "OK" : "error",
              status ? status->error_message().c_str() : "(does not parse)");
  ++written;
}

void Cube(v1::Mesh* mesh, double scale) {
  const double v[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  const int t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                   3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  for (double x : v) mesh->add_vertices(scale * x);
  for (int i : t) mesh->add_triangles(i);
}

void Poses(v1::PoseArray* poses, int count) {
  for (int i = 0; i < count; ++i) {
    for (double x : {1.0, 0.0, 0.0, 0.0, 0.5 * i, 0.25, 0.0}) poses->add_values(x);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_request_seeds DIR\n");
    return 64;
  }
  const std::string dir = argv[1];
  inscribe::fuzz::FuzzServer& server = inscribe::fuzz::TheFuzzServer();

  v1::InspectMeshRequest inspect;
  Cube(inspect.mutable_mesh(), 1.0);
  Seed(dir, RequestKind::kInspectMesh, inspect, "cube");
  inspect.mutable_mesh()->set_vertices(4, std::nan(""));
  inspect.set_skip_self_intersections(true);
  Seed(dir, RequestKind::kInspectMesh, inspect, "nan");

  v1::PutMeshRequest put;
  Cube(put.mutable_mesh(), 2.0);
  put.mutable_mesh()->mutable_triangles()->Truncate(33);  // one triangle short: a hole
  put.set_fill_holes(true);
  Seed(dir, RequestKind::kPutMesh, put, "hole");
  put.mutable_mesh()->add_vertices(1.0);  // not a multiple of 3
  Seed(dir, RequestKind::kPutMesh, put, "ragged");

  v1::GenerateRequest generate;
  generate.set_mesh_sha256(server.mesh_key);
  generate.mutable_parameters()->set_voxel_size(0.5);
  generate.set_progress_interval(0.01);
  Seed(dir, RequestKind::kGenerate, generate, "voxel");
  generate.mutable_parameters()->set_voxel_size(0.0);
  generate.mutable_parameters()->set_max_spheres(20);
  generate.mutable_parameters()->set_subdivide_boundary(true);
  generate.mutable_parameters()->set_dilate(true);
  generate.mutable_parameters()->set_dilation_growth(0.5);
  Seed(dir, RequestKind::kGenerate, generate, "budget");
  generate.mutable_parameters()->set_dilate(false);
  generate.mutable_parameters()->clear_dilation_growth();
  generate.mutable_parameters()->set_cover(true);
  generate.mutable_parameters()->set_cover_resolution(1.0 / 64);
  Seed(dir, RequestKind::kGenerate, generate, "cover");

  v1::PutSphereSetRequest put_set;
  for (double x : {0.5, 0.5, 0.5, 0.25, 0.25, 0.25}) put_set.mutable_spheres()->add_centers(x);
  put_set.mutable_spheres()->add_radii(0.5);
  put_set.mutable_spheres()->add_radii(0.25);
  for (int i : {0, 4}) put_set.mutable_spheres()->add_contact_triangles(i);
  for (double w : {0.2, 0.3, 0.5, 1.0, 0.0, 0.0}) {
    put_set.mutable_spheres()->add_contact_barycentrics(w);
  }
  put_set.set_mesh_sha256(server.mesh_key);
  Seed(dir, RequestKind::kPutSphereSet, put_set, "contacts");

  v1::GetSphereSetRequest get_set;
  get_set.set_sphere_set_key(server.sphere_set_key);
  Seed(dir, RequestKind::kGetSphereSet, get_set, "generated");

  v1::GetHierarchyRequest hierarchy;
  hierarchy.set_sphere_set_key(server.plain_set_key);
  hierarchy.set_volume(v1::RSS);
  Seed(dir, RequestKind::kGetHierarchy, hierarchy, "rss");

  v1::UpdateDeformationRequest deform;
  deform.set_mesh_sha256(server.mesh_key);
  deform.set_sphere_set_key(server.sphere_set_key);
  v1::Mesh stretched;
  Cube(&stretched, 1.1);
  *deform.mutable_vertices() = stretched.vertices();
  deform.set_bounds(true);
  deform.set_store(true);
  Seed(dir, RequestKind::kUpdateDeformation, deform, "stretch");
  deform.set_strict(true);
  deform.set_interpolated_normal(true);
  deform.set_xi(0.01);
  Seed(dir, RequestKind::kUpdateDeformation, deform, "strict");

  v1::DistanceRequest distance;
  distance.set_sphere_set_a(server.sphere_set_key);
  distance.set_sphere_set_b(server.plain_set_key);
  Poses(distance.mutable_poses_a(), 1);
  Poses(distance.mutable_poses_b(), 3);
  distance.mutable_tolerance()->set_rel_err(0.01);
  Seed(dir, RequestKind::kDistance, distance, "poses");
  distance.mutable_poses_a()->Clear();
  Poses(distance.mutable_poses_a(), 3);
  distance.set_volume(v1::RSS);
  distance.mutable_tolerance()->set_closer_than(0.5);
  Seed(dir, RequestKind::kDistance, distance, "closer");

  v1::DistanceRequest certified = distance;
  certified.set_cover_a(server.cover_set_key);
  certified.set_cover_b(server.cover_set_key);
  certified.set_sphere_set_b(server.sphere_set_key);
  certified.set_volume(v1::SPHERE);
  certified.mutable_tolerance()->set_rel_err(0.0);  // certified distances are exact
  Seed(dir, RequestKind::kDistance, certified, "certified");

  v1::PutSphereSetRequest put_cover;
  put_cover.mutable_spheres()->add_centers(0.5);
  put_cover.mutable_spheres()->add_centers(0.5);
  put_cover.mutable_spheres()->add_centers(0.5);
  put_cover.mutable_spheres()->add_radii(1.0);
  put_cover.mutable_certificate()->set_certified(true);
  put_cover.mutable_certificate()->set_delta(0.5);
  put_cover.mutable_certificate()->set_resolution(1.0 / 512);
  put_cover.mutable_certificate()->add_protrusions(0.5);
  put_cover.mutable_certificate()->set_mesh_sha256(server.mesh_key);
  put_cover.mutable_certificate()->set_spheres_sha256(inscribe::FormatSha256(
      inscribe::SpheresSha256({inscribe::Sphere{inscribe::Vector3::Constant(0.5), 1.0}})));
  Seed(dir, RequestKind::kPutSphereSet, put_cover, "certificate");

  v1::DistanceFrame frame;
  frame.set_frame(7);
  for (const std::string& b : {server.plain_set_key, server.sphere_set_key}) {
    v1::DistancePair* pair = frame.add_pairs();
    pair->set_sphere_set_a(server.sphere_set_key);
    pair->set_sphere_set_b(b);
    pair->mutable_pose_a()->set_qw(1.0);
    pair->mutable_pose_b()->set_qw(1.0);
    pair->mutable_pose_b()->set_tx(2.0);
  }
  Seed(dir, RequestKind::kDistanceStream, frame, "pairs");
  for (v1::DistancePair& pair : *frame.mutable_pairs()) {
    pair.set_sphere_set_b(server.sphere_set_key);
    pair.set_cover_a(server.cover_set_key);
    pair.set_cover_b(server.cover_set_key);
  }
  frame.mutable_tolerance()->set_closer_than(0.25);
  Seed(dir, RequestKind::kDistanceStream, frame, "certified");

  v1::EvaluateRequest evaluate;
  evaluate.set_mesh_sha256(server.mesh_key);
  evaluate.set_sphere_set_key(server.sphere_set_key);
  evaluate.set_samples(500);
  Seed(dir, RequestKind::kEvaluate, evaluate, "key");
  *evaluate.mutable_sphere_set() = put_set.spheres();
  evaluate.set_coverage_tolerance(0.01);
  evaluate.set_voxel_size(0.5);
  Seed(dir, RequestKind::kEvaluate, evaluate, "inline");

  Seed(dir, RequestKind::kCacheStats, v1::CacheStatsRequest(), "empty");

  v1::CertifyCoverRequest certify;
  certify.set_mesh_sha256(server.mesh_key);
  certify.set_sphere_set_key(server.sphere_set_key);
  certify.set_resolution(1.0 / 64);
  Seed(dir, RequestKind::kCertifyCover, certify, "key");
  *certify.mutable_sphere_set() = put_set.spheres();
  Seed(dir, RequestKind::kCertifyCover, certify, "inline");
  std::printf("%d seeds in %s\n", written, dir.c_str());
  std::fflush(stdout);
  std::_Exit(0);  // the fuzzing server is never stopped (see TheFuzzServer)
}
