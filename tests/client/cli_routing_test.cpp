// `inscribe generate --server A,B,C` against three real inscribed processes: the same spheres
// as with one server, also when one of the listed replicas is not running.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "support/inscribed_process.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

namespace fs = std::filesystem;

class CliRouting : public ::testing::Test {
 protected:
  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("knot1.off");
    dir_ = fs::temp_directory_path() / ("inscribe-cli-routing-" + std::to_string(::getpid()) + "-" +
                                        std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    for (int i = 0; i < 3; ++i) {
      replicas_.push_back(std::make_unique<testing::InscribedProcess>(
          INSCRIBED, std::vector<std::string>{"--listen", "127.0.0.1:0", "--jobs", "1"}));
      ASSERT_TRUE(replicas_.back()->started());
      addresses_.push_back(replicas_.back()->WaitUntilListening());
      ASSERT_FALSE(addresses_.back().empty()) << replicas_.back()->log();
      replicas_.back()->DrainLogInBackground();
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `generate` of data/<mesh> at 5% of its bounding-box diagonal through `servers`; the CSV
  // sphere file it wrote (centres and radii only: no timings) and its JSON summary.
  std::pair<std::string, nlohmann::json> Generate(const std::string& mesh,
                                                  const std::string& servers) {
    const double voxel = 0.05 * ComputeBoundingBox(testing::LoadTestMesh(mesh).vertices).diagonal();
    const fs::path out = dir_ / (mesh + "." + std::to_string(runs_++) + ".csv");
    std::ostringstream args;
    args.precision(17);
    args << "generate --json --voxel-size " << voxel << " " << Quote(testing::TestMeshPath(mesh))
         << " -o " << Quote(out.string()) << " --server " << servers;
    const CliRun run = RunCli(args.str());
    EXPECT_EQ(run.exit_code, 0) << args.str() << "\n" << run.err;
    nlohmann::json summary = nlohmann::json::parse(run.out, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(summary.is_discarded()) << run.out;
    return {Slurp(out), summary};
  }

  fs::path dir_;
  int runs_ = 0;
  std::vector<std::unique_ptr<testing::InscribedProcess>> replicas_;
  std::vector<std::string> addresses_;
};

TEST_F(CliRouting, SeveralServersGiveTheSameSpheresAsOne) {
  const std::string all = addresses_[0] + "," + addresses_[1] + "," + addresses_[2];
  // A listed replica that is not running: its meshes fail over to their next replica.
  const std::string with_dead = addresses_[1] +
                                ",127.0.0.1:" + std::to_string(testing::UnusedLoopbackPort()) +
                                "," + addresses_[2];
  for (const std::string mesh : {"eight.off", "cube.off", "knot1.off"}) {
    SCOPED_TRACE(mesh);
    const auto [single, single_summary] = Generate(mesh, addresses_[0]);
    const auto [routed, routed_summary] = Generate(mesh, all);
    const auto [survived, survived_summary] = Generate(mesh, with_dead);
    ASSERT_FALSE(single.empty());
    EXPECT_GT(std::count(single.begin(), single.end(), '\n'), 2);
    EXPECT_EQ(routed, single);
    EXPECT_EQ(survived, single);
    ASSERT_TRUE(single_summary.contains("sphere_set_key")) << single_summary.dump();
    EXPECT_EQ(routed_summary.value("sphere_set_key", ""),
              single_summary.value("sphere_set_key", ""));
    EXPECT_EQ(survived_summary.value("sphere_set_key", ""),
              single_summary.value("sphere_set_key", ""));
  }
}

}  // namespace
}  // namespace inscribe
