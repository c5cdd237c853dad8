// `inscribe distance`, run as users run it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// Rows of a CSV answer, header dropped (and checked: the plain columns, then `extra`), split
// on commas.
std::vector<std::vector<std::string>> Rows(const std::string& csv, const std::string& extra = "") {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz" + extra);
  const std::size_t columns = 10 + std::count(extra.begin(), extra.end(), ',');
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    EXPECT_EQ(cells.size(), columns) << line;
    rows.push_back(cells);
  }
  return rows;
}

class CliDistance : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::TestMeshPath("eight.off").empty()) {
      GTEST_SKIP() << "eight.off is missing; run scripts/fetch-meshes";
    }
    dir_ = fs::temp_directory_path() / ("inscribe_cli_distance_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    json_ = (dir_ / "eight.json").string();
    csv_ = (dir_ / "eight.csv").string();
    const std::string mesh = Quote(testing::TestMeshPath("eight.off"));
    ASSERT_EQ(RunCli("generate " + mesh + " --max-spheres 120 -o " + Quote(json_)).exit_code, 0);
    ASSERT_EQ(RunCli("generate " + mesh + " --max-spheres 80 -o " + Quote(csv_)).exit_code, 0);
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
  fs::path dir_;
  std::string json_, csv_;
};

constexpr char kPoses[] =
    "# qw qx qy qz tx ty tz\n"
    "1 0 0 0 0 0 0\n"
    "\n"
    "0.7071 0 0 0.7071 3 0 0   # rounded quaternion: normalised\n"
    "1 0 0 0 0 0 5\n"
    "0 1 0 0 0.2 0.1 0\n";

TEST_F(CliDistance, EveryHierarchyGivesTheSameAnswers) {
  const std::string poses = Write("poses.txt", kPoses);
  std::vector<std::vector<std::vector<std::string>>> answers;
  for (const char* hierarchy : {"rss", "sphere", "none"}) {
    const CliRun run = RunCli("distance " + Quote(json_) + " " + Quote(csv_) + " --poses " +
                              Quote(poses) + " --hierarchy " + hierarchy);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    answers.push_back(Rows(run.out));
    ASSERT_EQ(answers.back().size(), 4u);
  }
  for (std::size_t pose = 0; pose < 4; ++pose) {
    const double rss = std::stod(answers[0][pose][1]);
    EXPECT_NEAR(std::stod(answers[1][pose][1]), rss, 1e-9) << pose;
    EXPECT_NEAR(std::stod(answers[2][pose][1]), rss, 1e-9) << pose;
  }
  EXPECT_LT(std::stod(answers[0][0][1]), 0.0);  // a copy on itself overlaps
  EXPECT_GT(std::stod(answers[0][2][1]), 0.0);  // 5 units away along z
}

TEST_F(CliDistance, JsonSummaryAndCsvFile) {
  const std::string poses = Write("poses.txt", kPoses);
  const std::string out = (dir_ / "out.csv").string();
  const CliRun run = RunCli("distance " + Quote(json_) + " " + Quote(json_) + " --poses " +
                            Quote(poses) + " --json -o " + Quote(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("queries"), 4);
  EXPECT_GT(j.at("seconds").get<double>(), 0.0);
  EXPECT_GT(j.at("us_per_query").get<double>(), 0.0);
  EXPECT_EQ(j.at("hierarchy"), "sphere");
  EXPECT_EQ(j.at("touching"), 2);
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(Rows(text.str()).size(), 4u);

  const CliRun closer = RunCli("distance " + Quote(json_) + " " + Quote(json_) + " --poses " +
                               Quote(poses) + " --closer-than 0.5 --json");
  ASSERT_EQ(closer.exit_code, 0) << closer.err;
  EXPECT_EQ(nlohmann::json::parse(closer.out).at("closer"), 2);
}

// --cover-a/--cover-b: each row gains lower,upper (and closer with --closer-than), an interval
// that holds the exact distance: the internal sets' distance is at least upper (they lie
// inside the solids); a cover whose file records no certificate is proved with --mesh-a/-b.
TEST_F(CliDistance, CoversAddCertifiedIntervals) {
  const std::string mesh = Quote(testing::TestMeshPath("eight.off"));
  const std::string cover = (dir_ / "cover.json").string();
  ASSERT_EQ(RunCli("generate " + mesh + " --cover --max-spheres 60 -o " + Quote(cover)).exit_code,
            0);
  const std::string poses = Write("poses.txt", kPoses);
  const std::string base = "distance " + Quote(json_) + " " + Quote(json_) + " --poses " +
                           Quote(poses) + " --cover-a " + Quote(cover) + " --cover-b ";
  const CliRun run = RunCli(base + Quote(cover));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto rows = Rows(run.out, ",lower,upper");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    const double distance = std::stod(row[1]), lower = std::stod(row[10]),
                 upper = std::stod(row[11]);
    EXPECT_GE(lower, 0.0) << row[0];
    EXPECT_LE(lower, upper) << row[0];
    EXPECT_LE(upper, std::max(0.0, distance) + 1e-9) << row[0];
  }
  // Poses 0 and 3 overlap: 0 is an answer; pose 2 is 5 apart along z.
  EXPECT_EQ(std::stod(rows[0][10]), 0.0);
  EXPECT_GT(std::stod(rows[2][10]), 0.0);

  const CliRun closer = RunCli(base + Quote(cover) + " --closer-than 0.5");
  ASSERT_EQ(closer.exit_code, 0) << closer.err;
  const auto answered = Rows(closer.out, ",lower,upper,closer");
  EXPECT_EQ(answered[0][12], "yes");
  EXPECT_EQ(answered[2][12], "no");
  const CliRun summary = RunCli(base + Quote(cover) + " --closer-than 0.5 --json");
  ASSERT_EQ(summary.exit_code, 0) << summary.err;
  const nlohmann::json j = nlohmann::json::parse(summary.out);
  EXPECT_TRUE(j.at("certified").get<bool>());
  EXPECT_EQ(j.at("closer_yes").get<int>() + j.at("closer_no").get<int>() +
                j.at("closer_undecided").get<int>(),
            4);
  EXPECT_GE(j.at("mean_width").get<double>(), 0.0);
  EXPECT_LE(j.at("mean_width").get<double>(), j.at("max_width").get<double>());

  // The same cover as CSV records no certificate: refused, then proved with the mesh, giving
  // the same intervals (the service's delta is the file's).
  const std::string csv_cover = (dir_ / "cover.csv").string();
  ASSERT_EQ(RunCli("convert " + Quote(cover) + " -o " + Quote(csv_cover)).exit_code, 0);
  const CliRun unproved = RunCli(base + Quote(csv_cover));
  EXPECT_EQ(unproved.exit_code, 64);
  EXPECT_THAT(unproved.err, HasSubstr("records no cover certificate"));
  EXPECT_THAT(unproved.err, HasSubstr("--mesh-b"));
  const CliRun proved = RunCli(base + Quote(csv_cover) + " --mesh-b " + mesh);
  ASSERT_EQ(proved.exit_code, 0) << proved.err;
  EXPECT_EQ(proved.out, run.out);
}

TEST_F(CliDistance, CoverCombinationsThatCannotHoldAreRefused) {
  const std::string mesh = Quote(testing::TestMeshPath("eight.off"));
  const std::string cover = (dir_ / "cover.json").string();
  const std::string dilated = (dir_ / "dilated.json").string();
  ASSERT_EQ(RunCli("generate " + mesh + " --cover --max-spheres 60 -o " + Quote(cover)).exit_code,
            0);
  ASSERT_EQ(
      RunCli("generate " + mesh + " --dilate --max-spheres 60 -o " + Quote(dilated)).exit_code, 0);
  const std::string poses = " --poses " + Quote(Write("poses.txt", kPoses));
  const std::string pair = "distance " + Quote(json_) + " " + Quote(json_) + poses;
  const std::string covers = " --cover-a " + Quote(cover) + " --cover-b " + Quote(cover);
  struct Case {
    std::string command;
    int exit_code;
    std::string message;
  };
  const Case cases[] = {
      {pair + " --cover-a " + Quote(cover), 64, "requires"},
      {pair + " --mesh-a " + mesh, 64, "requires"},
      {pair + covers + " --hierarchy none", 64, "exact already"},
      {pair + covers + " --abs-err 0.01", 64, "abs_err"},
      {"distance " + Quote(dilated) + " " + Quote(json_) + poses + covers, 64,
       "holds dilated spheres"},
      // Internal spheres are no cover: the service's proof gives a point they miss.
      {pair + " --cover-a " + Quote(json_) + " --mesh-a " + mesh + " --cover-b " + Quote(cover), 1,
       "is not a cover of"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command);
    const CliRun run = RunCli(c.command);
    EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message));
    EXPECT_EQ(run.out, "");
  }
}

TEST_F(CliDistance, RefusesBadInput) {
  const std::string base = "distance " + Quote(json_) + " " + Quote(csv_) + " --poses ";
  CliRun run = RunCli(base + Quote(Write("short.txt", "1 0 0 0 0 0 0\n1 0 0 0 0 0\n")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("line 2: expected 7 numbers"));
  run = RunCli(base + Quote(Write("norm.txt", "2 0 0 0 0 0 0\n")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("line 1: quaternion"));
  run = RunCli(base + Quote(Write("word.txt", "1 0 0 zero 0 0 0\n")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("'zero' is not a number"));
  run = RunCli(base + Quote(Write("nan.txt", "1 0 0 0 nan 0 0\n")));
  EXPECT_EQ(run.exit_code, 2);
  run = RunCli(base + Quote(Write("empty.txt", "# nothing\n")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("no poses"));
  run = RunCli(base + Quote((dir_ / "missing.txt").string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("missing.txt"));
  run = RunCli("distance " + Quote(Write("junk.json", "{not json")) + " " + Quote(csv_) +
               " --poses " + Quote(Write("p.txt", kPoses)));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(RunCli(base + Quote(Write("p2.txt", kPoses)) + " --hierarchy octree").exit_code, 64);
  EXPECT_EQ(RunCli("distance " + Quote(json_)).exit_code, 64);
}

// A cover file's certificate names its spheres and mesh: a file whose spheres were edited after
// `generate --cover` wrote it, or whose recorded hash was, is refused without the mesh, and with
// the mesh certified again. On a box, whose exact distance to a translated (or half-turned)
// copy is the gap between their extents: every interval given must hold it.
class CliCoverBinding : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("inscribe_cli_binding_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    mesh_ = (dir_ / "box.off").string();
    ASSERT_TRUE(WriteMesh(mesh_, testing::Box(Vector3::Zero(), kSize)).ok());
    ASSERT_TRUE(WriteMesh((dir_ / "other.off").string(),
                          testing::Box(Vector3::Zero(), Vector3::Constant(2.0)))
                    .ok());
    internal_ = (dir_ / "internal.json").string();
    cover_ = (dir_ / "cover.json").string();
    ASSERT_EQ(
        RunCli("generate " + Quote(mesh_) + " --max-spheres 40 -o " + Quote(internal_)).exit_code,
        0);
    const CliRun cover =
        RunCli("generate " + Quote(mesh_) + " --cover --max-spheres 30 -o " + Quote(cover_));
    ASSERT_EQ(cover.exit_code, 0) << cover.err;
    poses_ = (dir_ / "poses.txt").string();
    std::ofstream(poses_) << "1 0 0 0 3 0 0\n"
                             "1 0 0 0 0 0 2\n"
                             "1 0 0 0 1.5 1 0.8\n"
                             "1 0 0 0 0.2 0.1 0\n"
                             "0 0 0 1 3 0.6 0\n";  // half a turn about z
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // The exact distance between the box and its copy at pose i of poses_: per axis, the gap
  // between the extents ([0, size], and the copy's moved and, for the half turn, flipped in x
  // and y).
  static double ExactDistance(std::size_t pose) {
    const double t[5][3] = {{3, 0, 0}, {0, 0, 2}, {1.5, 1, 0.8}, {0.2, 0.1, 0}, {3, 0.6, 0}};
    double squared = 0.0;
    for (int k = 0; k < 3; ++k) {
      const bool flipped = pose == 4 && k < 2;
      const double lo = flipped ? t[pose][k] - kSize[k] : t[pose][k];
      const double gap = std::max({lo - kSize[k], -(lo + kSize[k]), 0.0});
      squared += gap * gap;
    }
    return std::sqrt(squared);
  }

  CliRun Distance(const std::string& cover_a, const std::string& extra = "") {
    return RunCli("distance " + Quote(internal_) + " " + Quote(internal_) + " --poses " +
                  Quote(poses_) + " --cover-a " + Quote(cover_a) + " --cover-b " + Quote(cover_) +
                  extra);
  }

  // Every row's interval holds the exact distance.
  static void ExpectIntervalsHold(const CliRun& run) {
    const auto rows = Rows(run.out, ",lower,upper");
    ASSERT_EQ(rows.size(), 5u);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double lower = std::stod(rows[i][10]), upper = std::stod(rows[i][11]);
      EXPECT_LE(lower, ExactDistance(i) + 1e-9) << i;
      EXPECT_GE(upper, ExactDistance(i) - 1e-9) << i;
    }
  }

  // cover_ with `edit` applied, written as `name`.
  std::string Edited(const std::string& name, const std::function<void(SphereFile&)>& edit) {
    absl::StatusOr<SphereFile> file = ReadSphereFile(cover_);
    EXPECT_TRUE(file.ok()) << file.status();
    edit(*file);
    const std::string path = (dir_ / name).string();
    const absl::Status written = WriteSphereFile(path, *file);
    EXPECT_TRUE(written.ok()) << written;
    return path;
  }

  static inline const Vector3 kSize = Vector3(1.0, 0.6, 0.4);
  fs::path dir_;
  std::string mesh_, internal_, cover_, poses_;
};

TEST_F(CliCoverBinding, EditedCoversAreRefusedWithoutTheMeshAndCertifiedAgainWithIt) {
  const CliRun as_written = Distance(cover_);
  ASSERT_EQ(as_written.exit_code, 0) << as_written.err;
  ExpectIntervalsHold(as_written);
  // With the mesh, a certificate of these spheres and this mesh is used as it is.
  const CliRun with_mesh = Distance(cover_, " --mesh-a " + Quote(mesh_));
  ASSERT_EQ(with_mesh.exit_code, 0) << with_mesh.err;
  EXPECT_EQ(with_mesh.out, as_written.out);
  EXPECT_EQ(with_mesh.err, "");

  const auto scale_radii = [](double scale) {
    return [scale](SphereFile& f) {
      for (Sphere& s : f.set.spheres) s.radius *= scale;
    };
  };
  const auto set_stat = [](const std::string& name, const std::string& value) {
    return [name, value](SphereFile& f) {
      for (auto& [key, held] : f.stats) {
        if (key == name) held = value;
      }
    };
  };
  struct Case {
    std::string name;
    std::function<void(SphereFile&)> edit;
    const char* why;
    int exit_with_mesh;  // -1: 0 or 1, as the proof finds
  };
  const std::vector<Case> cases = {
      {"grown.json", scale_radii(1.03), "edited after they were certified", 0},
      {"shrunk.json", scale_radii(0.97), "edited after they were certified", 1},
      {"nudged.json", [](SphereFile& f) { f.set.spheres[0].center.x() += 1e-6; }, "other spheres",
       -1},
      {"dropped.json",
       [](SphereFile& f) {
         f.set.spheres.pop_back();
         f.protrusions.pop_back();
       },
       "other spheres", -1},
      {"hash_edited.json", set_stat("certified_spheres_sha256", "sha256:" + std::string(64, 'f')),
       "other spheres", 0},
      {"unbound.json",
       [](SphereFile& f) {
         const auto hash = [](const auto& stat) {
           return stat.first == "certified_mesh_sha256" || stat.first == "certified_spheres_sha256";
         };
         f.stats.erase(std::remove_if(f.stats.begin(), f.stats.end(), hash), f.stats.end());
       },
       "names no", 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = Edited(c.name, c.edit);
    const CliRun refused = Distance(path);
    EXPECT_EQ(refused.exit_code, 2) << refused.err;
    EXPECT_EQ(refused.out, "");
    EXPECT_THAT(refused.err, HasSubstr(path));
    EXPECT_THAT(refused.err, HasSubstr(c.why));
    EXPECT_THAT(refused.err, HasSubstr("--mesh-a MESH"));

    const CliRun proved = Distance(path, " --mesh-a " + Quote(mesh_));
    EXPECT_THAT(proved.err, HasSubstr("certifying it against"));
    if (c.exit_with_mesh != -1) EXPECT_EQ(proved.exit_code, c.exit_with_mesh) << proved.err;
    if (proved.exit_code == 0) {
      ExpectIntervalsHold(proved);
    } else {
      EXPECT_EQ(proved.exit_code, 1) << proved.err;
      EXPECT_THAT(proved.err, HasSubstr("is not a cover of"));
      EXPECT_EQ(proved.out, "");
    }
  }

  // Another mesh given: the certificate is not of that mesh, so the cover is proved against
  // it, and it does not hold the larger box.
  const std::string other = (dir_ / "other.off").string();
  const CliRun other_mesh = Distance(cover_, " --mesh-a " + Quote(other));
  EXPECT_EQ(other_mesh.exit_code, 1) << other_mesh.err;
  EXPECT_THAT(other_mesh.err, HasSubstr("proved against mesh"));
  EXPECT_THAT(other_mesh.err, HasSubstr("is not a cover of"));
}

}  // namespace
}  // namespace inscribe
