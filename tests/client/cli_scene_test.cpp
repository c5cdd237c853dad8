// `inscribe scene`, run as users run it: a scene of CGAL's demo meshes (sphere files and a
// mesh generated in the scene), a pose log replayed over it, embedded and against an inscribed
// process; answers checked against brute force; bad files named with their line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/inscribed_process.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

constexpr double kThreshold = 0.05;

class CliScene : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::TestMeshPath("eight.off").empty()) {
      GTEST_SKIP() << "eight.off is missing; run scripts/fetch-meshes";
    }
    dir_ = fs::temp_directory_path() / ("inscribe_cli_scene_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    spheres_ = (dir_ / "eight.json").string();
    const std::string mesh = Quote(testing::TestMeshPath("eight.off"));
    ASSERT_EQ(RunCli("generate " + mesh + " --max-spheres 60 -o " + Quote(spheres_)).exit_code, 0);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // Objects 1 and 2: the sphere file (by a path relative to the scene file); object 3:
  // generated from the mesh, in group 2 with mask 1, so that it meets object 1 (group 1) but
  // not object 2 (group 4).
  std::string Scene() {
    nlohmann::json scene = {
        {"format", "inscribe.scene"},
        {"version", 1},
        {"threshold", kThreshold},
        {"objects",
         {{{"id", 1}, {"spheres", "eight.json"}},
          {{"id", 2}, {"spheres", "eight.json"}, {"group", 4}, {"pose", {1, 0, 0, 0, 3, 0, 0}}},
          {{"id", 3},
           {"mesh", testing::TestMeshPath("eight.off")},
           {"max_spheres", 40},
           {"group", 2},
           {"mask", 1},
           {"pose", {1, 0, 0, 0, 0, 3, 0}}}}}};
    return Write("scene.json", scene.dump(1));
  }

  // Object 2 walks towards object 1 along x, from 1.25 to 0.8 times the set's extent and back;
  // object 3 spins in place. The poses of object 2, by frame.
  std::string PoseLog(std::map<std::int64_t, RigidPose>* poses_2) {
    absl::StatusOr<SphereFile> file = ReadSphereFile(spheres_);
    EXPECT_TRUE(file.ok()) << file.status();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Sphere& s : file->set.spheres) {
      lo = std::min(lo, s.center.x() - s.radius);
      hi = std::max(hi, s.center.x() + s.radius);
    }
    const double extent = hi - lo;
    std::ostringstream log;
    log << std::setprecision(17) << "frame,id,qw,qx,qy,qz,tx,ty,tz\n# object 2 approaches\n";
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> jitter(-0.02, 0.02);
    for (int frame = 0; frame < 30; ++frame) {
      const double x = extent * (0.8 + 0.03 * std::abs(frame - 15) + jitter(rng));
      const double angle = 0.1 * frame;
      log << frame << ",2,1,0,0,0," << x << ",0.1,0\n";
      (*poses_2)[frame] = RigidPose{Eigen::Quaterniond::Identity(), Vector3(x, 0.1, 0)};
      if (frame % 3 == 0) {
        log << frame << ",3," << std::cos(angle / 2) << ",0,0," << std::sin(angle / 2)
            << ",0,3,0\n";
      }
    }
    return Write("poses.csv", log.str());
  }

  fs::path dir_;
  std::string spheres_;
};

// The CSV and the JSON agree, and every (1, 2) distance is brute force's over the file's
// spheres; frames where it is below the threshold, and only those, report the pair.
void CheckAgainstBruteForce(const CliRun& csv, const CliRun& json, const std::string& spheres,
                            const std::map<std::int64_t, RigidPose>& poses_2) {
  ASSERT_EQ(json.exit_code, 0) << json.err;
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  const nlohmann::json frames = nlohmann::json::parse(json.out);
  ASSERT_EQ(frames.size(), 30u);
  absl::StatusOr<SphereFile> file = ReadSphereFile(spheres);
  ASSERT_TRUE(file.ok()) << file.status();
  std::istringstream rows(csv.out);
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "frame,a,b,distance,lower,upper,certified,sphere_a,sphere_b,ax,ay,az,bx,by,bz");
  std::size_t csv_rows = 0;
  while (std::getline(rows, line)) ++csv_rows;
  std::size_t json_pairs = 0, close_12 = 0;
  for (const nlohmann::json& frame : frames) {
    const std::int64_t number = frame["frame"];
    absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(
        file->set.spheres, RigidPose{}, file->set.spheres, poses_2.at(number));
    ASSERT_TRUE(brute.ok());
    bool found = false;
    for (const nlohmann::json& pair : frame["pairs"]) {
      ++json_pairs;
      EXPECT_LT(pair["a"].get<int>(), pair["b"].get<int>());
      EXPECT_NE(pair["b"].get<int>() == 3 && pair["a"].get<int>() == 2, true) << "masked pair";
      if (pair["a"] == 1 && pair["b"] == 2) {
        found = true;
        EXPECT_NEAR(pair["distance"].get<double>(), brute->distance, 1e-9) << number;
        EXPECT_FALSE(pair["certified"].get<bool>());
        EXPECT_TRUE(pair["upper"].is_null());
      }
    }
    EXPECT_EQ(found, brute->distance < kThreshold) << number << ": " << brute->distance;
    close_12 += found;
  }
  EXPECT_EQ(csv_rows, json_pairs);
  EXPECT_GT(close_12, 3u) << "the walk should bring 1 and 2 close";
  EXPECT_LT(close_12, 30u) << "... and apart";
  const nlohmann::json summary = nlohmann::json::parse(json.err.substr(json.err.rfind('{')));
  EXPECT_EQ(summary["frames"], 30);
  EXPECT_EQ(summary["objects"], 3);
  EXPECT_EQ(summary["pairs"], json_pairs);
  EXPECT_GE(summary["p99_ms"].get<double>(), summary["p50_ms"].get<double>());
}

TEST_F(CliScene, ReplaysAPoseLogLikeBruteForce) {
  std::map<std::int64_t, RigidPose> poses_2;
  const std::string args = Quote(Scene()) + " " + Quote(PoseLog(&poses_2));
  CheckAgainstBruteForce(RunCli("scene " + args), RunCli("scene " + args + " --json"), spheres_,
                         poses_2);
}

TEST_F(CliScene, ServerAnswersAsEmbedded) {
  testing::InscribedProcess server(INSCRIBED, {"--listen", "127.0.0.1:0", "--jobs", "2"});
  ASSERT_TRUE(server.started());
  const std::string address = server.WaitUntilListening();
  ASSERT_FALSE(address.empty());
  server.DrainLogInBackground();
  std::map<std::int64_t, RigidPose> poses_2;
  const std::string args = Quote(Scene()) + " " + Quote(PoseLog(&poses_2)) + " --server " + address;
  CheckAgainstBruteForce(RunCli("scene " + args), RunCli("scene " + args + " --json"), spheres_,
                         poses_2);
}

// Bad files end with a clear error naming the file and line (or object) and a nonzero exit.
TEST_F(CliScene, BadFilesAreNamedWithTheirLine) {
  const std::string scene = Scene();
  const std::string poses = Write("one.csv", "0,1,1,0,0,0,0,0,0\n");
  struct Case {
    std::string scene, poses, says;
  };
  const std::vector<Case> cases = {
      {Write("broken.json", "{\"format\": \"inscribe.scene\",\n\"version\": 1,\n\"objects\": [}"),
       poses, "broken.json: line 3"},
      {Write("dup.json", R"({"format": "inscribe.scene", "version": 1, "objects":
           [{"id": 1, "spheres": "eight.json"}, {"id": 1, "spheres": "eight.json"}]})"),
       poses, "objects[1]: id 1 is used twice"},
      {Write("nofile.json", R"({"format": "inscribe.scene", "version": 1, "objects":
           [{"id": 1, "spheres": "missing.json"}]})"),
       poses, "missing.json"},
      {Write("pose.json", R"({"format": "inscribe.scene", "version": 1, "objects":
           [{"id": 4, "spheres": "eight.json", "pose": [0, 0, 0, 0, 1, 2, 3]}]})"),
       poses, "objects[0] (id 4): pose"},
      {Write("ignore.json", R"({"format": "inscribe.scene", "version": 1, "objects":
           [{"id": 1, "spheres": "eight.json"}], "ignore": [[1, 5]]})"),
       poses, "ignore[0]: no object with id 5"},
      {scene, Write("fields.csv", "frame,id,qw,qx,qy,qz,tx,ty,tz\n0,1,1,0,0,0,0,0\n"),
       "fields.csv: line 2: expected 9 fields"},
      {scene, Write("unknown.csv", "0,1,1,0,0,0,0,0,0\n\n1,7,1,0,0,0,0,0,0\n"),
       "unknown.csv: line 3: no object with id 7"},
      {scene, Write("order.csv", "2,1,1,0,0,0,0,0,0\n1,1,1,0,0,0,0,0,0\n"),
       "order.csv: line 2: frame 1 after frame 2"},
      {scene, Write("twice.csv", "0,1,1,0,0,0,0,0,0\n0,1,1,0,0,0,1,0,0\n"),
       "twice.csv: line 2: object 1 moves twice in frame 0"},
      {scene, Write("quat.csv", "0,1,2,0,0,0,0,0,0\n"), "quat.csv: line 1"},
      {scene, Write("nan.csv", "0,1,x,0,0,0,0,0,0\n"), "nan.csv: line 1: 'x' is not a number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.says);
    const CliRun run = RunCli("scene " + Quote(c.scene) + " " + Quote(c.poses));
    EXPECT_NE(run.exit_code, 0);
    EXPECT_THAT(run.err, HasSubstr(c.says));
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

// A scene's cover is used with its file's certificate only while the certificate names the
// cover's spheres: an edited cover is refused without the object's mesh and certified again
// with it. Two unit cubes 3 apart along x: the exact distance is 2.
TEST(CliSceneCovers, EditedCoversAreRefusedOrCertifiedAgain) {
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_scene_covers_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string mesh = (dir / "cube.off").string();
  ASSERT_TRUE(WriteMesh(mesh, testing::UnitCube()).ok());
  const std::string internal = (dir / "internal.json").string(),
                    cover = (dir / "cover.json").string();
  ASSERT_EQ(RunCli("generate " + Quote(mesh) + " --max-spheres 30 -o " + Quote(internal)).exit_code,
            0);
  ASSERT_EQ(
      RunCli("generate " + Quote(mesh) + " --cover --max-spheres 30 -o " + Quote(cover)).exit_code,
      0);
  for (const double scale : {0.97, 1.03}) {
    absl::StatusOr<SphereFile> file = ReadSphereFile(cover);
    ASSERT_TRUE(file.ok()) << file.status();
    for (Sphere& s : file->set.spheres) s.radius *= scale;
    const std::string name = scale < 1.0 ? "shrunk.json" : "grown.json";
    ASSERT_TRUE(WriteSphereFile((dir / name).string(), *file).ok());
  }
  const std::string poses = (dir / "poses.csv").string();
  std::ofstream(poses) << "0,2,1,0,0,0,3,0,0\n";
  // Object 2's cover `cover_2`, with the cube's mesh when `with_mesh`.
  const auto scene = [&](const std::string& cover_2, bool with_mesh) {
    nlohmann::json second = {{"id", 2}, {"spheres", "internal.json"}, {"cover", cover_2}};
    if (with_mesh) second["mesh"] = "cube.off";
    const nlohmann::json j = {
        {"format", "inscribe.scene"},
        {"version", 1},
        {"threshold", 5.0},
        {"objects", {{{"id", 1}, {"spheres", "internal.json"}, {"cover", "cover.json"}}, second}}};
    const std::string path = (dir / "scene.json").string();
    std::ofstream(path) << j.dump();
    return RunCli("scene " + Quote(path) + " " + Quote(poses) + " --json");
  };
  const auto expect_interval = [](const CliRun& run) {
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json frames = nlohmann::json::parse(run.out);
    ASSERT_EQ(frames.size(), 1u);
    ASSERT_EQ(frames[0]["pairs"].size(), 1u);
    const nlohmann::json& pair = frames[0]["pairs"][0];
    EXPECT_TRUE(pair["certified"].get<bool>());
    EXPECT_LE(pair["lower"].get<double>(), 2.0 + 1e-9);
    EXPECT_GE(pair["upper"].get<double>(), 2.0 - 1e-9);
  };

  expect_interval(scene("cover.json", false));
  const CliRun refused = scene("shrunk.json", false);
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_THAT(refused.err, HasSubstr("shrunk.json"));
  EXPECT_THAT(refused.err, HasSubstr("edited after they were certified"));
  EXPECT_THAT(refused.err, HasSubstr("give the object's mesh"));
  // With the mesh: proved again, and 0.97 of every radius no longer holds the cube.
  const CliRun not_a_cover = scene("shrunk.json", true);
  EXPECT_EQ(not_a_cover.exit_code, 1) << not_a_cover.err;
  EXPECT_THAT(not_a_cover.err, HasSubstr("not a cover"));
  const CliRun grown = scene("grown.json", true);
  EXPECT_THAT(grown.err, HasSubstr("certifying it against"));
  expect_interval(grown);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace inscribe
