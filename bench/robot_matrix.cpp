// The self-collision matrix (robot/include/inscribe/robot/self_collision.h) on a 7-link arm of
// CGAL demo meshes (tests/support/mesh_arm.h: six revolute joints, links 0.1-0.25 m), with
// certified covers per link, against FCL mesh-mesh collision checks (BVHModel<OBBRSS> +
// fcl::collide) of the same samples and link pairs, both parallel (TBB) on the same threads.
// Before timing, every pair the matrix calls "never" is checked with FCL on every sample it
// timed: a colliding one fails the program (exit 1), so the smoke run is also a soundness check.
// Prints a Markdown table.
//
//   robot_matrix [--samples 10000,100000] [--totals 64,224] [--fcl-samples N] [--seed S]
//                [--data DIR] [--quick]
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/urdf_spherize.h"
#include "inscribe/solid/mesh_validation.h"
#include "support/fcl_solid_distance.h"
#include "support/mesh_arm.h"

namespace {

using inscribe::robot::CollisionPairClass;
using inscribe::robot::Kinematics;
using inscribe::robot::LinkPairCollision;
using inscribe::robot::SelfCollisionMatrix;

constexpr double kTargetSeconds = 5.0;   // 100,000 samples
constexpr double kTargetSpeedup = 20.0;  // against FCL on the same samples and pairs

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct FclRun {
  double seconds = 0.0;
  std::int64_t checks = 0;
  std::vector<std::int64_t> colliding;  // per pair of the matrix
};

// fcl::collide on every pair of the matrix at the first `samples` configurations of the
// matrix's sampler, in parallel over samples.
FclRun FclCollisions(const Kinematics& kinematics, const SelfCollisionMatrix& matrix,
                     const std::vector<inscribe::testing::FclSolid>& fcl, std::int64_t samples) {
  const auto configurations =
      inscribe::robot::SampleConfigurations(kinematics, samples, matrix.seed);
  const std::size_t pairs = matrix.pairs.size();
  FclRun run;
  const auto start = std::chrono::steady_clock::now();
  run.colliding = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, configurations.size(), 16),
      std::vector<std::int64_t>(pairs, 0),
      [&](const tbb::blocked_range<std::size_t>& range, std::vector<std::int64_t> counts) {
        std::vector<Eigen::Isometry3d> poses;
        for (std::size_t s = range.begin(); s < range.end(); ++s) {
          if (!kinematics.LinkPoses(configurations[s], &poses).ok()) std::abort();
          for (std::size_t k = 0; k < pairs; ++k) {
            const LinkPairCollision& pair = matrix.pairs[k];
            const auto pose = [&](int link) {
              return inscribe::RigidPose{Eigen::Quaterniond(poses[link].linear()),
                                         poses[link].translation()};
            };
            counts[k] += inscribe::testing::SurfacesCollide(fcl[pair.link_a], pose(pair.link_a),
                                                            fcl[pair.link_b], pose(pair.link_b));
          }
        }
        return counts;
      },
      [](std::vector<std::int64_t> a, const std::vector<std::int64_t>& b) {
        for (std::size_t k = 0; k < a.size(); ++k) a[k] += b[k];
        return a;
      });
  run.seconds = Since(start);
  run.checks = static_cast<std::int64_t>(configurations.size() * pairs);
  return run;
}

std::vector<std::int64_t> ParseList(const std::string& text) {
  std::vector<std::int64_t> values;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t comma = text.find(',', at);
    values.push_back(std::stoll(text.substr(at, comma - at)));
    at = comma == std::string::npos ? text.size() : comma + 1;
  }
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Self-collision matrix of a 7-link demo-mesh arm against FCL collision checks");
  std::string samples_text = "10000,100000", totals_text = "64,224";
  std::int64_t fcl_samples = 0;
  std::uint64_t seed = 1;
  std::string data_dir = INSCRIBE_SOURCE_DIR "/data";
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) data_dir = env;
  bool quick = false;
  app.add_option("--samples", samples_text, "Sample counts, comma-separated");
  app.add_option("--totals", totals_text,
                 "Sphere budgets for the whole arm, shared evenly among the 7 links");
  app.add_option("--fcl-samples", fcl_samples,
                 "Samples FCL checks (0: as many as the matrix; fewer: its time is scaled up)");
  app.add_option("--seed", seed, "Sampler seed");
  app.add_option("--data", data_dir, "Directory of the demo meshes");
  app.add_flag("--quick", quick, "Smoke run: 2,000 samples, 64 spheres");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    samples_text = "2000";
    totals_text = "64";
  }
  const std::vector<std::int64_t> sample_counts = ParseList(samples_text);
  const std::vector<std::int64_t> totals = ParseList(totals_text);

  std::vector<inscribe::Mesh> meshes;
  for (const std::string& model : inscribe::testing::MeshArmModels()) {
    absl::StatusOr<inscribe::Mesh> mesh = inscribe::ReadMesh(data_dir + "/" + model);
    if (!mesh.ok()) {
      absl::FPrintF(stderr, "robot_matrix: %s: %s\n", model, mesh.status().message());
      return 1;
    }
    absl::StatusOr<inscribe::ValidatedMesh> valid = inscribe::PrepareMesh(*std::move(mesh));
    if (!valid.ok()) {
      absl::FPrintF(stderr, "robot_matrix: %s: %s\n", model, valid.status().message());
      return 1;
    }
    meshes.push_back(std::move(valid->mesh));
  }
  absl::StatusOr<inscribe::testing::MeshArm> arm =
      inscribe::testing::BuildMeshArm(meshes, inscribe::testing::MeshArmJoints::kRevolute);
  if (!arm.ok()) {
    absl::FPrintF(stderr, "robot_matrix: %s\n", arm.status().message());
    return 1;
  }
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(arm->robot);
  if (!kinematics.ok()) return 1;
  std::vector<inscribe::testing::FclSolid> fcl;
  std::int64_t triangles = 0;
  for (const inscribe::Solid& solid : arm->solids) {
    fcl.push_back(inscribe::testing::MakeFclSolid(solid));
    triangles += solid.mesh().triangles.rows();
  }

  absl::PrintF("Arm: 7 links (%s), %d triangles in all, 6 revolute joints, %d pairs.\n\n",
               absl::StrJoin(inscribe::testing::MeshArmModels(), ", "), triangles, 21);

  // The whole robot through `inscribe urdf`'s pipeline (SpherizeRobot): each link's mesh written
  // as a file its link's <collision> names, read, validated and covered again.
  {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / absl::StrCat("robot_matrix_", ::getpid());
    fs::create_directories(dir);
    inscribe::robot::UrdfRobot urdf = arm->robot;
    for (std::size_t l = 0; l < urdf.links.size(); ++l) {
      const std::string path = (dir / absl::StrCat("link", l, ".off")).string();
      if (!inscribe::WriteMesh(path, arm->solids[l].mesh()).ok()) return 1;
      inscribe::robot::UrdfElement element;
      element.geometry.shape = inscribe::robot::UrdfShape::kMesh;
      element.geometry.filename = path;
      urdf.links[l].elements = {element};
    }
    absl::PrintF(
        "Whole-robot spherization (SpherizeRobot, certified covers, meshes read from files):\n\n"
        "| mode | spheres | largest delta mm | links' deltas mm | seconds |\n"
        "|---|---:|---:|---|---:|\n");
    for (const std::int64_t total : totals) {
      for (const bool shared : {true, false}) {
        inscribe::robot::UrdfSpherizeOptions options;
        if (shared) {
          options.max_spheres = total;
        } else {
          options.max_spheres_per_link = std::max<std::int64_t>(1, total / 7);
        }
        const auto start = std::chrono::steady_clock::now();
        absl::StatusOr<inscribe::robot::RobotSpherizeResult> result =
            inscribe::robot::SpherizeRobot(urdf, options);
        const double seconds = Since(start);
        if (!result.ok()) {
          absl::FPrintF(stderr, "robot_matrix: spherize: %s\n", result.status().message());
          return 1;
        }
        std::size_t spheres = 0;
        double largest = 0.0;
        std::vector<std::string> deltas;
        for (const auto& link : result->links) {
          if (link.status != inscribe::robot::LinkStatus::kSpherized || !link.delta) return 1;
          spheres += link.spheres.size();
          largest = std::max(largest, *link.delta);
          deltas.push_back(absl::StrFormat("%.1f", 1000 * *link.delta));
        }
        absl::PrintF("| %s %d | %d | %.1f | %s | %.2f |\n",
                     shared ? "--max-spheres" : "--max-spheres-per-link",
                     shared ? total : *options.max_spheres_per_link, spheres, 1000 * largest,
                     absl::StrJoin(deltas, " "), seconds);
      }
    }
    absl::PrintF("\n");
    fs::remove_all(dir);
  }
  absl::PrintF(
      "| spheres (per link) | cover s | max delta mm | samples | pairs checked | matrix s | FCL s "
      "| FCL / matrix | never | sometimes | always | default | adjacent |\n");
  absl::PrintF("|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  // Targets, on the first budget's 100,000-sample rows: [0] all pairs, [1] adjacent skipped.
  bool seconds_met[2] = {true, true}, speedup_met[2] = {true, true}, measured = false;
  bool failed = false;
  for (const std::int64_t total : totals) {
    const std::int64_t per_link = std::max<std::int64_t>(1, total / 7);
    absl::StatusOr<inscribe::testing::MeshArmCovers> covers =
        inscribe::testing::CoverMeshArm(*arm, per_link, 0.0);
    if (!covers.ok()) {
      absl::FPrintF(stderr, "robot_matrix: cover: %s\n", covers.status().message());
      return 1;
    }
    std::size_t spheres = 0;
    double max_delta = 0.0;
    for (const auto& link : covers->links) {
      spheres += link.spheres.size();
      max_delta = std::max(max_delta, *link.certified_delta);
    }
    for (const std::int64_t samples : sample_counts) {
      for (const bool sample_adjacent : {true, false}) {
        inscribe::robot::SelfCollisionOptions options;
        options.samples = samples;
        options.seed = seed;
        options.sample_adjacent = sample_adjacent;
        absl::StatusOr<SelfCollisionMatrix> matrix =
            inscribe::robot::ComputeSelfCollisionMatrix(*kinematics, covers->links, options);
        if (!matrix.ok()) {
          absl::FPrintF(stderr, "robot_matrix: %s\n", matrix.status().message());
          return 1;
        }
        const std::int64_t checked = fcl_samples > 0 ? std::min(fcl_samples, samples) : samples;
        const FclRun run = FclCollisions(*kinematics, *matrix, fcl, checked);
        const double fcl_seconds = run.seconds * static_cast<double>(samples) / checked;
        int counts[5] = {0, 0, 0, 0, 0};
        for (std::size_t k = 0; k < matrix->pairs.size(); ++k) {
          const LinkPairCollision& pair = matrix->pairs[k];
          ++counts[static_cast<int>(pair.type)];
          // Soundness: the covers hold the solids, so FCL sees no contact where they are apart.
          if (pair.sampled && pair.colliding_samples == 0 && run.colliding[k] > 0) {
            absl::FPrintF(stderr,
                          "robot_matrix: pair %s-%s never collides by the matrix, FCL "
                          "finds %d contacts\n",
                          matrix->links[pair.link_a], matrix->links[pair.link_b], run.colliding[k]);
            failed = true;
          }
        }
        const double speedup = fcl_seconds / matrix->seconds;
        if (samples >= 100'000 && total == totals.front()) {
          measured = true;
          seconds_met[!sample_adjacent] &= matrix->seconds <= kTargetSeconds;
          speedup_met[!sample_adjacent] &= speedup >= kTargetSpeedup;
        }
        absl::PrintF(
            "| %d (%d) | %.2f | %.1f | %d | %s | %.3f | %.2f%s | %.0fx | %d | %d | %d | %d | %d "
            "|\n",
            spheres, per_link, covers->seconds, 1000 * max_delta, samples,
            sample_adjacent ? "all" : "adjacent skipped", matrix->seconds, fcl_seconds,
            checked < samples ? "*" : "", speedup,
            counts[static_cast<int>(CollisionPairClass::kNever)],
            counts[static_cast<int>(CollisionPairClass::kSometimes)],
            counts[static_cast<int>(CollisionPairClass::kAlways)],
            counts[static_cast<int>(CollisionPairClass::kDefault)],
            counts[static_cast<int>(CollisionPairClass::kAdjacent)]);
      }
    }
  }
  if (fcl_samples > 0) absl::PrintF("\n* FCL timed on %d samples, scaled up.\n", fcl_samples);
  const auto verdict = [&](bool met) {
    return !measured ? "not measured" : met ? "met" : "NOT met";
  };
  for (int mode = 0; mode < 2; ++mode) {
    absl::PrintF(
        "\n%s, %d spheres: target \"100,000-sample matrix <= %.0f s\": %s; target "
        "\">= %.0fx faster than FCL on the same samples and pairs\": %s.",
        mode == 0 ? "All pairs" : "Adjacent pairs skipped", totals.front(), kTargetSeconds,
        verdict(seconds_met[mode]), kTargetSpeedup, verdict(speedup_met[mode]));
  }
  absl::PrintF("\n");
  return failed ? 1 : 0;
}
