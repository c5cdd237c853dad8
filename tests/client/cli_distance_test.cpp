// `inscribe distance`, run as users run it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
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
  // Rows of a CSV answer, header dropped (and checked: the plain columns, then `extra`), split
  // on commas.
  static std::vector<std::vector<std::string>> Rows(const std::string& csv,
                                                    const std::string& extra = "") {
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

}  // namespace
}  // namespace inscribe
