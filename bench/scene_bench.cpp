// Simulator scenes: N objects drawn from the CGAL demo meshes move randomly inside a
// box; every frame sets all their poses and asks for every pair closer than a threshold, with
// its distance. Timed in-process (core's Scene on TBB's threads, and on one thread) next to
// FCL's broad-phase manager on the same poses and the same meshes: DynamicAABBTreeCollisionManager
// over AABBs grown by the threshold, then fcl::distance on every pair it hands over (the same
// answer: every pair closer than the threshold, with its distance), and collision alone
// (fcl::collide on the pairs whose AABBs overlap). Optional rows with certified objects
// (covers and their cores: intervals instead of distances). The same scenes run over the
// service too: an inscribed on loopback in this process, one SceneSession (SceneStream) per
// scene sending every pose every frame, each reply checked against core's Scene.
//
// Every model is scaled so that its bounding box's largest side is 1; the box's side is chosen
// so that each object has a few neighbours within reach (`--spacing` object sizes between
// neighbouring centres). Each frame every object moves by up to `--step` of its size and turns
// by up to `--turn` radians, bouncing off the box's walls.
//
//   scene_bench [--models eight,cow,...] [--objects 16,64,256] [--frames N] [--fcl-frames N]
//               [--spheres N] [--threshold T] [--certified] [--no-service] [--check-every K]
//               [--queries distance,certified,contact] [--seed S]
//
// Exit status: 0 every check passed (targets are reported, not enforced); 1 a frame (every
// K-th) differs from the brute force over all pairs of objects and all pairs of spheres, a
// certified frame misses a pair FCL finds closer, or a service reply differs from core's
// Scene or fails; 2 a model could not be prepared or the server not started.
#include "scene_bench.h"

#include <fcl/fcl.h>
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "inscribe/client/client.h"
#include "inscribe/client/connection.h"
#include "inscribe/cover/sphere_cover.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/scene/scene.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/solid/solid.h"
#include "support/fcl_solid_distance.h"

namespace inscribe::scene_bench {

using testing::BuildFclMesh;
using testing::FclMesh;
using testing::ToFcl;

constexpr double kTargetFps = 1000.0;    // a 64-object scene
constexpr double kTargetSpeedup = 30.0;  // against FCL's broad plus narrow phase
constexpr double kAgreement = 1e-9;

Mesh ScaledToUnitBox(Mesh mesh) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double scale = 1.0 / box.extent().maxCoeff();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = ((mesh.vertices.row(i).transpose() - centre) * scale).transpose();
  }
  return mesh;
}

absl::StatusOr<std::shared_ptr<const SphereHierarchy>> Share(std::vector<Sphere> spheres) {
  absl::StatusOr<SphereHierarchy> h =
      SphereHierarchy::Build(std::move(spheres), HierarchyVolume::kSphere);
  if (!h.ok()) return h.status();
  return std::make_shared<const SphereHierarchy>(*std::move(h));
}

absl::StatusOr<Model> PrepareModel(const std::string& name, const Options& options) {
  absl::StatusOr<Mesh> read = ReadMesh(options.data_dir + "/" + name + ".off");
  if (!read.ok()) return read.status();
  SolidOptions solid_options;
  solid_options.validate.repair.level = MeshRepair::kFill;  // pig.off is open
  absl::StatusOr<Solid> solid = PrepareSolid(ScaledToUnitBox(*std::move(read)), solid_options);
  if (!solid.ok()) return solid.status();
  Model model;
  model.name = name;
  model.triangles = solid->mesh().num_triangles();
  model.fcl = BuildFclMesh(solid->mesh());
  SphereSetParameters parameters;
  parameters.kind = SphereSetKind::kDilated;
  parameters.max_spheres = options.spheres;
  parameters.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> dilated = GenerateSphereSet(*solid, parameters);
  if (!dilated.ok()) return dilated.status();
  absl::StatusOr<std::shared_ptr<const SphereHierarchy>> spheres = Share(dilated->set.spheres);
  if (!spheres.ok()) return spheres.status();
  model.spheres = *spheres;
  model.dilated_set = dilated->set;
  if (options.certified) {
    parameters.kind = SphereSetKind::kCover;
    absl::StatusOr<GeneratedSphereSet> cover = GenerateSphereSet(*solid, parameters);
    if (!cover.ok()) return cover.status();
    absl::StatusOr<std::vector<Sphere>> cores =
        UpperBoundSpheres({}, cover->set.spheres, cover->cover->certificate.protrusions);
    if (!cores.ok()) return cores.status();
    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> internal = Share(*cores);
    if (!internal.ok()) return internal.status();
    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> covering = Share(cover->set.spheres);
    if (!covering.ok()) return covering.status();
    model.internal = *internal;
    model.cover = *covering;
    model.cover_delta = cover->cover->certificate.delta;
    model.cores_set.spheres = *cores;
    model.cover_set = cover->set;
    model.certificate = cover->cover->certificate;
  }
  return model;
}

Motion MakeMotion(int objects, int frames, std::size_t models, const Options& options,
                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  Motion m;
  m.box = options.spacing * std::cbrt(static_cast<double>(objects));
  std::vector<RigidPose> now(static_cast<std::size_t>(objects));
  std::vector<Vector3> velocity(now.size());
  const auto random_direction = [&] {
    Vector3 v(normal(rng), normal(rng), normal(rng));
    return Vector3(v.normalized());
  };
  for (std::size_t i = 0; i < now.size(); ++i) {
    m.model.push_back(i % models);
    now[i].rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
    now[i].rotation.normalize();
    now[i].translation = Vector3(unit(rng), unit(rng), unit(rng)) * m.box;
    velocity[i] = random_direction() * options.step * unit(rng);
  }
  for (int f = 0; f < frames; ++f) {
    for (std::size_t i = 0; i < now.size(); ++i) {
      // The velocity drifts; walls reflect it.
      velocity[i] =
          (velocity[i] + 0.2 * options.step * random_direction()).normalized() * options.step;
      Vector3& t = now[i].translation;
      t += velocity[i];
      for (int k = 0; k < 3; ++k) {
        if (t[k] < 0.0 || t[k] > m.box) {
          velocity[i][k] = -velocity[i][k];
          t[k] = std::clamp(t[k], 0.0, m.box);
        }
      }
      const Eigen::Quaterniond spin(
          Eigen::AngleAxisd(options.turn * unit(rng), random_direction()));
      now[i].rotation = (spin * now[i].rotation).normalized();
    }
    m.pose.push_back(now);
  }
  return m;
}

// Per frame, the pairs (smaller index first) FCL found closer than the threshold (its exact
// mesh distance) or in contact.
using FramePairs = std::vector<std::vector<std::pair<SceneObjectId, SceneObjectId>>>;

Timing Summarise(std::vector<double> seconds, double candidates, double close) {
  Timing t;
  if (seconds.empty()) return t;
  double total = 0.0;
  for (double s : seconds) total += s;
  t.fps = static_cast<double>(seconds.size()) / total;
  std::sort(seconds.begin(), seconds.end());
  t.p50_us = 1e6 * seconds[seconds.size() / 2];
  t.p99_us = 1e6 * seconds[std::min(seconds.size() - 1, seconds.size() * 99 / 100)];
  t.candidates = candidates / static_cast<double>(seconds.size());
  t.close = close / static_cast<double>(seconds.size());
  return t;
}

// The scene for a motion: object i has id i.
Scene MakeScene(const Motion& motion, const std::vector<Model>& models, bool certified) {
  Scene scene;
  for (std::size_t i = 0; i < motion.model.size(); ++i) {
    const Model& m = models[motion.model[i]];
    SceneObject o;
    o.id = i;
    o.spheres = m.spheres;
    if (certified) {
      o.internal = m.internal;
      o.cover = m.cover;
      o.cover_delta = m.cover_delta;
    }
    o.pose = motion.pose[0][i];
    if (!scene.Add(std::move(o)).ok()) std::abort();
  }
  return scene;
}

// The brute force over all pairs of objects and spheres (CertifiedDistances for certified
// pairs) at one frame; true when the scene's frame equals it.
bool MatchesBruteForce(const SceneFrame& frame, const Motion& motion, int f,
                       const std::vector<Model>& models, bool certified, double threshold,
                       bool stop_at_first) {
  std::map<std::pair<SceneObjectId, SceneObjectId>, ScenePair> expected;
  const auto& poses = motion.pose[static_cast<std::size_t>(f)];
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      const Model& a = models[motion.model[i]];
      const Model& b = models[motion.model[j]];
      ScenePair p;
      p.a = i;
      p.b = j;
      if (certified) {
        const CertifiedObject ca{a.internal.get(), a.cover.get(), a.cover_delta};
        const CertifiedObject cb{b.internal.get(), b.cover.get(), b.cover_delta};
        absl::StatusOr<double> margin = CertifiedDistanceMargin(ca, poses[i], cb, poses[j]);
        absl::StatusOr<DistanceResult> covers = BruteForceSeparationDistance(
            a.cover->spheres(), poses[i], b.cover->spheres(), poses[j]);
        if (!margin.ok() || !covers.ok()) return false;
        if (!(covers->distance - *margin < threshold)) continue;
        absl::StatusOr<std::vector<CertifiedDistanceResult>> interval =
            CertifiedDistances({CertifiedPair{&ca, &cb, poses[i], poses[j]}});
        if (!interval.ok()) return false;
        p.certified = true;
        p.lower = (*interval)[0].lower;
        p.upper = (*interval)[0].upper;
        p.result = *covers;
      } else {
        absl::StatusOr<DistanceResult> r = BruteForceSeparationDistance(
            a.spheres->spheres(), poses[i], b.spheres->spheres(), poses[j]);
        if (!r.ok()) return false;
        if (!(r->distance < threshold)) continue;
        p.result = *r;
      }
      expected[{p.a, p.b}] = p;
    }
  }
  if (expected.size() != frame.pairs.size()) {
    std::fprintf(stderr, "frame %d: %zu close pairs, brute force %zu\n", f, frame.pairs.size(),
                 expected.size());
    return false;
  }
  for (const ScenePair& p : frame.pairs) {
    const auto it = expected.find({p.a, p.b});
    const bool same =
        it != expected.end() &&
        (stop_at_first ? p.result.distance < threshold &&
                             p.result.distance >= it->second.result.distance - kAgreement
                       : std::abs(it->second.result.distance - p.result.distance) <= kAgreement) &&
        (!certified || (std::abs(it->second.lower - p.lower) <= kAgreement &&
                        std::abs(it->second.upper - p.upper) <= kAgreement));
    if (!same) {
      std::fprintf(stderr, "frame %d: pair (%llu, %llu) differs from the brute force\n", f,
                   static_cast<unsigned long long>(p.a), static_cast<unsigned long long>(p.b));
      return false;
    }
  }
  return true;
}

// Core's scene: every frame sets every pose and asks for the close pairs.
// With `exact` (FCL's close pairs of the first frames), a certified scene must report every
// one of them: its lower bound is at most the exact distance. `close_compared` gets the mean
// close pairs per frame over those frames.
Timing RunScene(const Motion& motion, const std::vector<Model>& models, bool certified,
                double threshold, bool stop_at_first, const Options& options, int frames,
                bool check, const FramePairs* exact, double* close_compared, int* failures) {
  Scene scene = MakeScene(motion, models, certified);
  SceneQuery query;
  query.threshold = threshold;
  query.stop_at_first = stop_at_first;
  std::vector<std::pair<SceneObjectId, RigidPose>> moves(motion.model.size());
  std::vector<double> seconds;
  double candidates = 0.0, close = 0.0;
  std::vector<std::pair<int, SceneFrame>> kept;
  for (int f = 0; f < frames; ++f) {
    const auto& poses = motion.pose[static_cast<std::size_t>(f)];
    const Clock::time_point start = Clock::now();
    for (std::size_t i = 0; i < poses.size(); ++i) moves[i] = {i, poses[i]};
    if (!scene.SetPoses(moves).ok()) std::abort();
    absl::StatusOr<SceneFrame> frame = scene.ClosePairs(query);
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    if (!frame.ok()) std::abort();
    candidates += static_cast<double>(frame->candidate_pairs);
    close += static_cast<double>(frame->close_pairs);
    // Kept for the checks after the timed loop, which would otherwise evict its caches.
    const bool compared = exact != nullptr && static_cast<std::size_t>(f) < exact->size();
    if (compared || (check && f % options.check_every == 0)) kept.emplace_back(f, *frame);
  }
  for (const auto& [f, frame] : kept) {
    if (exact != nullptr && static_cast<std::size_t>(f) < exact->size()) {
      *close_compared +=
          static_cast<double>(frame.close_pairs) / static_cast<double>(exact->size());
      if (certified) {
        for (const auto& pair : (*exact)[static_cast<std::size_t>(f)]) {
          const bool reported = std::any_of(
              frame.pairs.begin(), frame.pairs.end(),
              [&](const ScenePair& p) { return p.a == pair.first && p.b == pair.second; });
          if (!reported) {
            std::fprintf(stderr,
                         "frame %d: FCL finds (%llu, %llu) closer than %g; the certified "
                         "scene does not report it\n",
                         f, static_cast<unsigned long long>(pair.first),
                         static_cast<unsigned long long>(pair.second), threshold);
            ++*failures;
          }
        }
      }
    }
    if (check && f % options.check_every == 0 &&
        !MatchesBruteForce(frame, motion, f, models, certified, threshold, stop_at_first)) {
      ++*failures;
    }
  }
  return Summarise(std::move(seconds), candidates, close);
}

// FCL's manager: every frame sets every transform, updates the tree and runs `collide` with a
// callback doing the narrow phase. `distance`: AABBs grown by half the threshold each side,
// fcl::distance on every pair handed over, counted when closer than the threshold; else
// fcl::collide on every pair whose AABBs overlap.
Timing RunFcl(const Motion& motion, const std::vector<Model>& models, const Options& options,
              int frames, bool distance, FramePairs* close_pairs) {
  // FCL keeps an object's world AABB protected; a subclass grows it after computeAABB.
  struct Object : fcl::CollisionObjectd {
    using fcl::CollisionObjectd::CollisionObjectd;
    void Grow(double by) {
      aabb.min_ -= fcl::Vector3d::Constant(by);
      aabb.max_ += fcl::Vector3d::Constant(by);
    }
  };
  std::vector<std::unique_ptr<Object>> objects;
  for (std::size_t i = 0; i < motion.model.size(); ++i) {
    objects.push_back(std::make_unique<Object>(models[motion.model[i]].fcl));
    objects.back()->setUserData(reinterpret_cast<void*>(i));
  }
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::vector<fcl::CollisionObjectd*> raw;
  for (auto& o : objects) raw.push_back(o.get());
  const double grow = distance ? 0.5 * options.threshold : 0.0;
  const auto place = [&](int f) {
    const auto& poses = motion.pose[static_cast<std::size_t>(f)];
    for (std::size_t i = 0; i < objects.size(); ++i) {
      objects[i]->setTransform(ToFcl(poses[i]));
      objects[i]->computeAABB();
      objects[i]->Grow(grow);
    }
  };
  place(0);
  manager.registerObjects(raw);
  manager.setup();
  struct Data {
    double threshold;
    bool distance;
    std::int64_t candidates = 0, close = 0;
    std::vector<std::pair<SceneObjectId, SceneObjectId>> pairs;  // this frame's close pairs
  } data{options.threshold, distance, 0, 0, {}};
  const auto callback = [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* p) {
    Data& d = *static_cast<Data*>(p);
    ++d.candidates;
    if (d.distance) {
      fcl::DistanceRequestd request;
      request.rel_err = 0.0;
      request.abs_err = 0.0;
      fcl::DistanceResultd result;
      if (!(fcl::distance(a, b, request, result) < d.threshold)) return false;
    } else {
      fcl::CollisionRequestd request;
      fcl::CollisionResultd result;
      if (fcl::collide(a, b, request, result) == 0) return false;
    }
    ++d.close;
    const auto ia = reinterpret_cast<SceneObjectId>(a->getUserData());
    const auto ib = reinterpret_cast<SceneObjectId>(b->getUserData());
    d.pairs.emplace_back(std::min(ia, ib), std::max(ia, ib));
    return false;  // go on
  };
  std::vector<double> seconds;
  for (int f = 0; f < frames; ++f) {
    const Clock::time_point start = Clock::now();
    place(f);
    manager.update();
    data.pairs.clear();
    manager.collide(&data, callback);
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    close_pairs->push_back(data.pairs);
  }
  return Summarise(std::move(seconds), static_cast<double>(data.candidates),
                   static_cast<double>(data.close));
}

}  // namespace inscribe::scene_bench

int main(int argc, char** argv) {
  using namespace inscribe;
  using namespace inscribe::scene_bench;
  Options options;
  options.data_dir = INSCRIBE_SOURCE_DIR "/data";
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) options.data_dir = env;
  CLI::App app{"Scenes of many moving objects: core's Scene against FCL's broad-phase manager"};
  app.add_option("--models", options.models, "meshes of the data directory")->delimiter(',');
  app.add_option("--objects", options.objects, "scene sizes")->delimiter(',');
  app.add_option("--frames", options.frames, "frames per scene (core)")->check(CLI::PositiveNumber);
  app.add_option("--fcl-frames", options.fcl_frames, "frames per scene (FCL)")
      ->check(CLI::PositiveNumber);
  app.add_option("--spheres", options.spheres, "sphere budget per model")
      ->check(CLI::PositiveNumber);
  app.add_option("--threshold", options.threshold, "pairs closer than this, object sizes");
  app.add_option("--spacing", options.spacing, "object sizes between neighbouring centres");
  app.add_option("--step", options.step, "largest move per frame, object sizes");
  app.add_flag("--certified", options.certified, "also run scenes of certified objects");
  app.add_flag("!--no-service", options.service, "skip the rows over SceneStream");
  app.add_option("--check-every", options.check_every, "brute-force check every K-th frame")
      ->check(CLI::PositiveNumber);
  app.add_option("--queries", options.queries, "rows to run: distance, certified, contact")
      ->delimiter(',')
      ->check(CLI::IsMember({"distance", "certified", "contact"}));
  app.add_option("--seed", options.seed, "random seed");
  app.add_option("--data", options.data_dir, "directory of the .off meshes");
  CLI11_PARSE(app, argc, argv);

  std::vector<Model> prepared;
  for (const std::string& name : options.models) {
    const Clock::time_point start = Clock::now();
    absl::StatusOr<Model> m = PrepareModel(name, options);
    if (!m.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), std::string(m.status().message()).c_str());
      return 2;
    }
    std::fprintf(stderr, "%s: %lld triangles, %zu spheres%s (%.1f s)\n", name.c_str(),
                 static_cast<long long>(m->triangles), m->spheres->spheres().size(),
                 options.certified ? absl::StrFormat(", cover %zu, delta %.4f",
                                                     m->cover->spheres().size(), m->cover_delta)
                                         .c_str()
                                   : "",
                 std::chrono::duration<double>(Clock::now() - start).count());
    prepared.push_back(*std::move(m));
  }

  // The service rows: an inscribed on loopback in this process, the models' sets uploaded.
  std::unique_ptr<server::InscribeServer> local;
  std::optional<client::Client> client;
  if (options.service) {
    server::ServerOptions server_options;
    server_options.listen = "127.0.0.1:0";
    absl::StatusOr<std::unique_ptr<server::InscribeServer>> started =
        server::InscribeServer::Start(server_options);
    if (!started.ok()) {
      std::fprintf(stderr, "inscribed: %s\n", std::string(started.status().message()).c_str());
      return 2;
    }
    local = *std::move(started);
    client.emplace(client::MakeGrpcConnection(local->address()));
    for (Model& m : prepared) {
      absl::StatusOr<client::PutSphereSetResult> put = client->PutSphereSet(m.dilated_set);
      if (put.ok()) m.spheres_key = put->sphere_set_key;
      if (put.ok() && options.certified) {
        put = client->PutSphereSet(m.cores_set);
        if (put.ok()) m.cores_key = put->sphere_set_key;
        if (put.ok()) put = client->PutCertifiedCover(m.cover_set, m.certificate);
        if (put.ok()) m.cover_key = put->sphere_set_key;
      }
      if (!put.ok()) {
        std::fprintf(stderr, "%s: upload: %s\n", m.name.c_str(),
                     std::string(put.status().message()).c_str());
        return 2;
      }
    }
  }

  int failures = 0;
  std::printf("Scenes: %s; threshold %.3g object sizes; %zu models; frames: core %d, FCL %d\n\n",
              absl::StrJoin(options.objects, ", ").c_str(), options.threshold, prepared.size(),
              options.frames, options.fcl_frames);
  std::printf(
      "| objects | query | close pairs / frame (FCL frames) | FCL close pairs / frame | candidates "
      "/ frame | "
      "core fps | core p50 us | core p99 us | core 1-thread fps | FCL fps | FCL p99 us | core / "
      "FCL | >= %.0fx | >= %.0f fps | service fps | service p50 us | service p99 us |\n",
      kTargetSpeedup, kTargetFps);
  std::printf(
      "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---:|\n");
  for (const int n : options.objects) {
    const int frames = std::max(options.frames, options.fcl_frames);
    const Motion motion =
        MakeMotion(n, frames, prepared.size(), options, options.seed + static_cast<unsigned>(n));
    const auto wanted = [&](const char* query) {
      return std::find(options.queries.begin(), options.queries.end(), query) !=
             options.queries.end();
    };
    FramePairs fcl_close, fcl_contacts;
    const Timing fcl_distance =
        wanted("distance") || (wanted("certified") && options.certified)
            ? RunFcl(motion, prepared, options, options.fcl_frames, true, &fcl_close)
            : Timing{};
    const Timing fcl_collide = wanted("contact") ? RunFcl(motion, prepared, options,
                                                          options.fcl_frames, false, &fcl_contacts)
                                                 : Timing{};
    // Rows: every pair closer than the threshold with its distance (against FCL's distance on
    // the pairs its grown AABBs hand over), the same with certified intervals, and the pairs
    // in contact (threshold 0, stopping at the first overlapping sphere pair as FCL's
    // collision stops at its first contact; against FCL's collision).
    struct Row {
      const char* name;
      bool certified;
      double threshold;
      bool stop_at_first;
      const Timing& fcl;
      const FramePairs& fcl_pairs;
    };
    const Row rows[] = {{"distance", false, options.threshold, false, fcl_distance, fcl_close},
                        {"certified", true, options.threshold, false, fcl_distance, fcl_close},
                        {"contact", false, 0.0, true, fcl_collide, fcl_contacts}};
    for (const Row& row : rows) {
      if ((row.certified && !options.certified) || !wanted(row.name)) continue;
      double close_compared = 0.0, unused = 0.0;
      const Timing core =
          RunScene(motion, prepared, row.certified, row.threshold, row.stop_at_first, options,
                   options.frames, true, &row.fcl_pairs, &close_compared, &failures);
      Timing single;
      {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        single = RunScene(motion, prepared, row.certified, row.threshold, row.stop_at_first,
                          options, options.frames, false, nullptr, &unused, &failures);
      }
      const Timing service =
          client ? RunService(*client, motion, prepared, row.certified, row.threshold,
                              row.stop_at_first, options, options.frames, &failures)
                 : Timing{};
      const double ratio = core.fps / row.fcl.fps;
      std::printf(
          "| %d | %s | %.1f | %.1f | %.1f | %.0f | %.0f | %.0f | %.0f | %.1f | %.0f | %.1f | %s | "
          "%s | %.0f | %.0f | %.0f |\n",
          n, row.name, close_compared, row.fcl.close, core.candidates, core.fps, core.p50_us,
          core.p99_us, single.fps, row.fcl.fps, row.fcl.p99_us, ratio,
          ratio >= kTargetSpeedup ? "pass" : "FAIL",
          n != 64 ? "-" : (core.fps >= kTargetFps ? "pass" : "FAIL"), service.fps, service.p50_us,
          service.p99_us);
      std::fflush(stdout);
    }
  }
  std::printf(
      "\nFrames checked against the brute force, FCL's close pairs (certified) and core's "
      "Scene (service) (every %d-th): %d failed\n",
      options.check_every, failures);
  return failures == 0 ? 0 : 1;
}
