// `inscribe distance`, run as users run it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

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
  // Rows of a CSV answer, header dropped, split on commas.
  static std::vector<std::vector<std::string>> Rows(const std::string& csv) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz");
    while (std::getline(in, line)) {
      std::vector<std::string> cells;
      std::istringstream cells_in(line);
      for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
      EXPECT_EQ(cells.size(), 10u) << line;
      rows.push_back(cells);
    }
    return rows;
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

}  // namespace
}  // namespace inscribe
