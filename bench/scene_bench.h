// What scene_bench's parts share: its options, the prepared models, the objects' motion and a
// run's timing; the service rows (scene_bench_service.cpp) run on the same scenes as core's.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/scene/scene.h"
#include "support/fcl_solid_distance.h"

namespace inscribe::scene_bench {

using Clock = std::chrono::steady_clock;

struct Options {
  std::vector<std::string> models = {"eight", "cow", "elephant", "knot1", "fandisk", "pig"};
  std::vector<int> objects = {16, 64, 256};
  int frames = 2000;
  int fcl_frames = 100;
  std::int64_t spheres = 200;
  double threshold = 0.05;  // object sizes
  double spacing = 1.6;     // object sizes between neighbouring centres
  double step = 0.01;       // object sizes per frame
  double turn = 0.02;       // radians per frame
  bool certified = false;
  bool service = true;  // also over SceneStream
  std::vector<std::string> queries = {"distance", "certified", "contact"};
  int check_every = 100;
  std::uint64_t seed = 1;
  std::string data_dir;
};

// One model: its sphere sets' hierarchies and FCL's tree over the same (scaled) mesh.
struct Model {
  std::string name;
  std::int64_t triangles = 0;
  std::shared_ptr<const SphereHierarchy> spheres, internal, cover;
  double cover_delta = 0.0;
  std::shared_ptr<testing::FclMesh> fcl;
  // What the service rows upload: the dilated set, and with --certified the cores (the
  // internal set of a certified object) and the cover with its certificate.
  SphereSet dilated_set, cores_set, cover_set;
  CoverCertificate certificate;
  // The keys the server gave them.
  std::string spheres_key, cores_key, cover_key;
};

// Every object's pose at every frame: a random walk inside a box, the same for every run.
struct Motion {
  std::vector<std::size_t> model;            // per object
  std::vector<std::vector<RigidPose>> pose;  // [frame][object]
  double box = 0.0;
};

struct Timing {
  double fps = 0.0, p50_us = 0.0, p99_us = 0.0;
  double candidates = 0.0, close = 0.0;  // per frame, means
};

// Frame times (seconds) and per-frame sums as a Timing.
Timing Summarise(std::vector<double> seconds, double candidates, double close);

// The scene for a motion: object i has id i.
Scene MakeScene(const Motion& motion, const std::vector<Model>& models, bool certified);

// The same scene over the service (scene_bench_service.cpp); failures counted in `failures`.
Timing RunService(const client::Client& client, const Motion& motion,
                  const std::vector<Model>& models, bool certified, double threshold,
                  bool stop_at_first, const Options& options, int frames, int* failures);

}  // namespace inscribe::scene_bench
