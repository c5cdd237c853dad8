// `inscribe ... --server ADDR` against a real inscribed process: every subcommand must print
// what it prints in embedded mode (timings and the few figures the server does not send
// aside), and remote failures must say which server and exit with their own codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "client/cli_run.h"
#include "deformation_sequences.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/inscribed_process.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using Keys = std::set<std::string>;

// inscribed on a free loopback port with its own disk cache, its log drained in the
// background for as long as it runs.
class LoopbackServer {
 public:
  explicit LoopbackServer(const fs::path& cache_dir)
      : process_(INSCRIBED,
                 {"--listen", "127.0.0.1:0", "--jobs", "2", "--cache-dir", cache_dir.string()}) {
    if (!process_.started()) return;
    address_ = process_.WaitUntilListening();
    process_.DrainLogInBackground();
  }
  // "127.0.0.1:PORT", or "" when the server did not start.
  const std::string& address() const { return address_; }

 private:
  testing::InscribedProcess process_;
  std::string address_;
};

bool Close(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)});
}

// Field by field: every key of `embedded` but `ignored` (timings) and `embedded_only` must be
// in `remote` with the same value (numbers to 1e-9 relative, recursively); `remote` may add
// only `remote_only`.
void ExpectSameJson(const nlohmann::json& embedded, const nlohmann::json& remote,
                    const Keys& ignored, const Keys& embedded_only = {},
                    const Keys& remote_only = {"server"}, const std::string& where = "") {
  ASSERT_EQ(embedded.type(), remote.type()) << where;
  if (embedded.is_object()) {
    for (const auto& [key, value] : embedded.items()) {
      if (ignored.count(key) > 0) continue;
      if (embedded_only.count(key) > 0) {
        EXPECT_FALSE(remote.contains(key)) << where + key;
        continue;
      }
      ASSERT_TRUE(remote.contains(key)) << "remote lacks " << where + key;
      ExpectSameJson(value, remote.at(key), ignored, {}, {}, where + key + ".");
    }
    for (const auto& [key, value] : remote.items()) {
      EXPECT_TRUE(embedded.contains(key) || remote_only.count(key) > 0 || ignored.count(key) > 0)
          << "remote adds " << where + key;
    }
  } else if (embedded.is_array()) {
    ASSERT_EQ(embedded.size(), remote.size()) << where;
    for (std::size_t i = 0; i < embedded.size(); ++i) {
      ExpectSameJson(embedded[i], remote[i], ignored, {}, {}, where + std::to_string(i) + ".");
    }
  } else if (embedded.is_number_float() || remote.is_number_float()) {
    EXPECT_TRUE(Close(embedded.get<double>(), remote.get<double>()))
        << where << ": " << embedded << " vs " << remote;
  } else {
    EXPECT_EQ(embedded, remote) << where;
  }
}

// Sphere files written by the two modes: equal spheres and contacts (1e-9 relative), hashes,
// params, and stats but `timings` and `embedded_only`.
void ExpectSameSphereFile(const std::string& embedded_path, const std::string& remote_path,
                          const Keys& timings, const Keys& embedded_only = {}) {
  absl::StatusOr<SphereFile> a = ReadSphereFile(embedded_path);
  absl::StatusOr<SphereFile> b = ReadSphereFile(remote_path);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status() << " / " << b.status();
  EXPECT_EQ(a->mesh_sha256, b->mesh_sha256);
  ASSERT_EQ(a->set.size(), b->set.size());
  ASSERT_EQ(a->set.contacts.size(), b->set.contacts.size());
  for (std::size_t i = 0; i < a->set.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(Close(a->set.spheres[i].center[k], b->set.spheres[i].center[k])) << i;
    }
    EXPECT_TRUE(Close(a->set.spheres[i].radius, b->set.spheres[i].radius)) << i;
  }
  for (std::size_t i = 0; i < a->set.contacts.size(); ++i) {
    EXPECT_EQ(a->set.contacts[i].triangle, b->set.contacts[i].triangle) << i;
    EXPECT_TRUE(a->set.contacts[i].barycentric.isApprox(b->set.contacts[i].barycentric, 1e-9));
  }
  auto as_json = [](const NamedValues& values) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [name, value] : values) {
      std::visit([&j, &name = name](const auto& v) { j[name] = v; }, value);
    }
    return j;
  };
  ExpectSameJson(as_json(a->params), as_json(b->params), {}, {}, {});
  ExpectSameJson(as_json(a->stats), as_json(b->stats), timings, embedded_only, {});
}

// One server for the suite, and a directory with eight.off's spheres made in embedded mode.
class CliRemote : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("inscribe_cli_remote_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "cache");
    server_ = new LoopbackServer(dir_ / "cache");
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("eight.off");
    ASSERT_FALSE(server_->address().empty()) << "inscribed did not start";
  }

  static std::string Path(const std::string& name) { return (dir_ / name).string(); }
  static std::string Eight() { return Quote(testing::TestMeshPath("eight.off")); }
  static std::string Server() { return " --server " + server_->address(); }
  // Runs `args` embedded and remotely; both must exit `code`.
  static std::pair<CliRun, CliRun> RunBoth(const std::string& args, int code = 0) {
    std::pair<CliRun, CliRun> runs{RunCli(args), RunCli(args + Server())};
    EXPECT_EQ(runs.first.exit_code, code) << args << "\n" << runs.first.err;
    EXPECT_EQ(runs.second.exit_code, code) << args << " --server\n" << runs.second.err;
    return runs;
  }
  static void RunBothJson(const std::string& args, const Keys& ignored,
                          const Keys& embedded_only = {}, const Keys& remote_only = {"server"}) {
    const auto [embedded, remote] = RunBoth(args);
    ExpectSameJson(nlohmann::json::parse(embedded.out), nlohmann::json::parse(remote.out), ignored,
                   embedded_only, remote_only);
  }
  // eight.off's spheres, made embedded once.
  static std::string Spheres() {
    const std::string path = Path("eight_80.json");
    if (!fs::exists(path)) {
      EXPECT_EQ(RunCli("generate " + Eight() + " --max-spheres 80 -o " + path).exit_code, 0);
    }
    return path;
  }

  static inline fs::path dir_;
  static inline LoopbackServer* server_ = nullptr;
};

// What the server does not send (see generate_command.cpp) and what it adds.
const Keys kGenerateTimings = {"seconds", "generation_seconds", "load_seconds", "evaluate_seconds",
                               "dilation_seconds"};

TEST_F(CliRemote, InfoPrintsTheSameReport) {
  RunBothJson("info --json " + Eight(), {"seconds"});
  // Text: the same lines but the time.
  auto [embedded, remote] = RunBoth("info " + Eight());
  auto drop_time = [](const std::string& text) {
    return text.substr(0, text.find("checked in")) + text.substr(text.find("issues"));
  };
  EXPECT_EQ(drop_time(embedded.out), drop_time(remote.out));
  EXPECT_THAT(embedded.out, HasSubstr("sha256:"));
}

TEST_F(CliRemote, InfoOfAnUnusableMeshIsTheSameReportAndExitOne) {
  INSCRIBE_REQUIRE_MESH("cube-ouvert.off");
  const std::string open_cube = Quote(testing::TestMeshPath("cube-ouvert.off"));
  const auto [embedded, remote] = RunBoth("info --json " + open_cube, 1);
  const nlohmann::json j = nlohmann::json::parse(remote.out);
  EXPECT_FALSE(j.at("usable").get<bool>());
  ExpectSameJson(nlohmann::json::parse(embedded.out), j, {"seconds"});
  // --fill-holes goes to the server too (InspectMesh fill_holes): the same repaired report.
  RunBothJson("info --json --fill-holes " + open_cube, {"seconds"});
}

TEST_F(CliRemote, GenerateGivesTheSameSummary) {
  for (const std::string mode : {"--max-spheres 60", "--voxel-size 0.1 --dilate"}) {
    SCOPED_TRACE(mode);
    RunBothJson("generate --json " + mode + " " + Eight(), kGenerateTimings, {},
                {"server", "sphere_set_key", "cache"});
  }
}

TEST_F(CliRemote, GenerateWritesTheSameSphereFile) {
  // Every generate option goes over the wire: the files are the same but for the time.
  for (const std::string mode :
       {"--voxel-size 0.12", "--max-spheres 50 --dilate",
        "--max-spheres 40 --screen-samples 4 --no-corner-screen --pair-angle-margin 0.1 "
        "--max-voxels 100000 --quality-samples 5000 --samples 20 --object-angle 0.5",
        "--voxel-size 0.15 --dilate --dilation-growth 0 --subdivide-boundary"}) {
    SCOPED_TRACE(mode);
    const std::string tag = std::to_string(std::hash<std::string>()(mode));
    const std::string embedded = Path("embedded_" + tag + ".json");
    const std::string remote = Path("remote_" + tag + ".json");
    ASSERT_EQ(RunCli("generate " + Eight() + " " + mode + " -o " + embedded).exit_code, 0);
    const CliRun run = RunCli("generate " + Eight() + " " + mode + " -o " + remote + Server());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.out, "");
    ExpectSameSphereFile(embedded, remote, {"seconds", "dilation_seconds"});
  }
}

TEST_F(CliRemote, EvaluateGivesTheSameReport) {
  RunBothJson("evaluate --json " + Eight() + " " + Spheres(), {"evaluate_seconds"});
  RunBothJson("evaluate --json --samples 0 --voxel-size 0.05 " + Eight() + " " + Spheres(),
              {"evaluate_seconds"});
  // Exact coverage (tolerance 0) goes over the wire like any other tolerance.
  RunBothJson("evaluate --json --samples 3000 --coverage-tolerance 0 " + Eight() + " " + Spheres(),
              {"evaluate_seconds"});
  auto [embedded, remote] = RunBoth("evaluate " + Eight() + " " + Spheres());
  auto drop_time = [](const std::string& text) {
    return text.substr(0, text.find("evaluated in"));
  };
  EXPECT_EQ(drop_time(embedded.out), drop_time(remote.out));
}

TEST_F(CliRemote, DeformGivesTheSameSummaryAndSphereFile) {
  absl::StatusOr<Mesh> reference = ReadMesh(testing::TestMeshPath("eight.off"));
  ASSERT_TRUE(reference.ok()) << reference.status();
  const std::string twisted = Path("eight_twisted.off");
  ASSERT_TRUE(WriteMesh(twisted, Mesh{sequences::Deform(reference->vertices,
                                                        sequences::DeformationKind::kTwist, 1.0),
                                      reference->triangles})
                  .ok());
  const std::string args = "deform " + Eight() + " " + Spheres() + " " + twisted;
  for (const std::string options : {"", " --strict --xi 0.01"}) {
    SCOPED_TRACE(options);
    RunBothJson(args + options + " --json", {"seconds", "bounds_seconds", "load_seconds"});
  }
  const std::string embedded = Path("deformed_embedded.json"),
                    remote = Path("deformed_remote.json");
  ASSERT_EQ(RunCli(args + " -o " + embedded).exit_code, 0);
  const CliRun run = RunCli(args + " -o " + remote + Server());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ExpectSameSphereFile(embedded, remote, {"seconds", "bounds_seconds"});
}

TEST_F(CliRemote, DistanceGivesTheSameAnswers) {
  const std::string b = Path("eight_40.csv");
  ASSERT_EQ(RunCli("generate " + Eight() + " --max-spheres 40 -o " + b).exit_code, 0);
  const std::string poses = Path("poses.txt");
  std::ofstream(poses) << "1 0 0 0 0 0 0\n0.7071 0.7071 0 0 1.5 0 0\n"
                          "0.5 0.5 0.5 0.5 0 3 0.2\n1 0 0 0 -4 0 0\n";
  const std::string args = "distance " + Spheres() + " " + b + " --poses " + poses;
  for (const std::string hierarchy : {"sphere", "rss"}) {
    SCOPED_TRACE(hierarchy);
    // The work counts agree; the thread count is each service's.
    RunBothJson(args + " --json --hierarchy " + hierarchy,
                {"seconds", "us_per_query", "build_seconds", "threads"});
    // The CSV rows: the header, pose and sphere indices exactly, numbers to 1e-9.
    const auto [embedded, remote] = RunBoth(args + " --hierarchy " + hierarchy);
    std::istringstream e(embedded.out), r(remote.out);
    std::string e_line, r_line;
    int rows = 0;
    for (; std::getline(e, e_line); ++rows) {
      ASSERT_TRUE(std::getline(r, r_line));
      std::istringstream e_cells(e_line), r_cells(r_line);
      int column = 0;
      for (std::string ec, rc; std::getline(e_cells, ec, ','); ++column) {
        ASSERT_TRUE(std::getline(r_cells, rc, ','));
        if (rows == 0 || column == 0 || column == 2 || column == 3) {
          EXPECT_EQ(ec, rc) << e_line << "\n" << r_line;
        } else {
          EXPECT_TRUE(Close(std::stod(ec), std::stod(rc))) << e_line << "\n" << r_line;
        }
      }
      EXPECT_EQ(column, 10);
    }
    EXPECT_FALSE(std::getline(r, r_line));
    EXPECT_EQ(rows, 5);
  }
}

TEST_F(CliRemote, BruteForceDistanceGoesOverTheWire) {
  const std::string b = Path("eight_30.csv");
  ASSERT_EQ(RunCli("generate " + Eight() + " --max-spheres 30 -o " + b).exit_code, 0);
  const std::string poses = Path("poses_brute.txt");
  std::ofstream(poses) << "1 0 0 0 0 0 0\n0.7071 0.7071 0 0 1.5 0 0\n1 0 0 0 -4 0 0\n";
  const std::string args =
      "distance " + Spheres() + " " + b + " --poses " + poses + " --hierarchy none";
  const auto [embedded, remote] = RunBoth(args);
  // Every sphere pair either way: the same rows to the bit.
  EXPECT_EQ(embedded.out, remote.out);
  RunBothJson(args + " --json", {"seconds", "us_per_query", "build_seconds", "threads"});
}

TEST_F(CliRemote, BadGenerateOptionsAreUsageErrorsEitherWay) {
  for (const std::string bad :
       {"--screen-samples 5000", "--samples 1", "--dilate --dilation-growth 2",
        "--quality-samples -1", "--max-voxels 10 --voxel-size 0.01"}) {
    SCOPED_TRACE(bad);
    const auto [embedded, remote] = RunBoth("generate " + bad + " " + Eight(), 64);
    EXPECT_EQ(embedded.out, "");
    EXPECT_EQ(remote.out, "");
  }
}

TEST_F(CliRemote, ServerRefusalsSayWhichServerAndMapToExitCodes) {
  INSCRIBE_REQUIRE_MESH("cube-ouvert.off");
  // An open mesh: the server's PutMesh says FAILED_PRECONDITION, exit 1 as embedded.
  const auto [embedded, remote] =
      RunBoth("evaluate " + Quote(testing::TestMeshPath("cube-ouvert.off")) + " " + Spheres(), 1);
  EXPECT_THAT(remote.err, HasSubstr("(server " + server_->address() + ": FAILED_PRECONDITION)"));
  // A mirror image of the reference is inside out: the server's INVALID_ARGUMENT for the
  // deformed vertices is exit 1, as the core's refusal is in embedded mode.
  absl::StatusOr<Mesh> mirrored = ReadMesh(testing::TestMeshPath("eight.off"));
  ASSERT_TRUE(mirrored.ok()) << mirrored.status();
  mirrored->vertices.col(0) *= -1.0;
  const std::string mirror = Path("eight_mirrored.off");
  ASSERT_TRUE(WriteMesh(mirror, *mirrored).ok());
  const auto [inverted_here, inverted_there] =
      RunBoth("deform " + Eight() + " " + Spheres() + " " + mirror, 1);
  EXPECT_THAT(inverted_there.err, HasSubstr("(server " + server_->address() + ": "));
  // No time to answer: DEADLINE_EXCEEDED, the "unreachable or too slow" status.
  const CliRun late = RunCli("generate --voxel-size 0.01 --timeout 0.001 " + Eight() + Server());
  EXPECT_EQ(late.exit_code, 69) << late.err;
  EXPECT_THAT(late.err, HasSubstr("DEADLINE_EXCEEDED"));
}

TEST(CliRemoteUnreachable, EveryCommandExits69NamingTheAddress) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const std::string address = "127.0.0.1:" + std::to_string(testing::UnusedLoopbackPort());
  const std::string eight = Quote(testing::TestMeshPath("eight.off"));
  for (const std::string& command : std::vector<std::string>{
           "info " + eight, "generate --voxel-size 0.2 " + eight, "stats", "stats --json"}) {
    SCOPED_TRACE(command);
    const CliRun run = RunCli(command + " --server " + address);
    EXPECT_EQ(run.exit_code, 69);
    EXPECT_THAT(run.err, HasSubstr("(server " + address + ": UNAVAILABLE)"));
    EXPECT_EQ(run.out, "");
  }
}

TEST(CliRemoteStats, CountsComputationsAndHits) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  // A server of its own, so that the counters start at zero.
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_stats_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    LoopbackServer server(dir);
    ASSERT_FALSE(server.address().empty());
    const std::string remote = " --server " + server.address();
    auto stats = [&remote] {
      const CliRun run = RunCli("stats --json" + remote);
      EXPECT_EQ(run.exit_code, 0) << run.err;
      return nlohmann::json::parse(run.out);
    };
    const nlohmann::json before = stats();
    for (const char* field :
         {"entries", "bytes", "memory_hits", "disk_hits", "hits", "misses", "computations",
          "joined", "evictions", "disk_entries", "disk_bytes", "disk_errors"}) {
      EXPECT_TRUE(before.contains(field)) << field;
    }
    EXPECT_EQ(before.at("computations"), 0);
    EXPECT_EQ(before.at("hits"), 0);

    const std::string generate =
        "generate --json --voxel-size 0.15 " + Quote(testing::TestMeshPath("eight.off")) + remote;
    const CliRun first = RunCli(generate);
    ASSERT_EQ(first.exit_code, 0) << first.err;
    EXPECT_EQ(nlohmann::json::parse(first.out).at("cache"), "computed");
    const nlohmann::json after_first = stats();
    EXPECT_GE(after_first.at("computations").get<int>(), 1);
    EXPECT_GE(after_first.at("entries").get<int>(), 1);
    EXPECT_GT(after_first.at("bytes").get<int>(), 0);

    const CliRun second = RunCli(generate);
    ASSERT_EQ(second.exit_code, 0) << second.err;
    EXPECT_EQ(nlohmann::json::parse(second.out).at("cache"), "memory");
    const nlohmann::json after_second = stats();
    EXPECT_GT(after_second.at("hits").get<int>(), after_first.at("hits").get<int>());
    EXPECT_EQ(after_second.at("computations"), after_first.at("computations"));

    // The text form lists every counter.
    const CliRun text = RunCli("stats" + remote);
    ASSERT_EQ(text.exit_code, 0) << text.err;
    EXPECT_THAT(text.out, HasSubstr("computations"));
    EXPECT_THAT(text.out, HasSubstr("disk_errors"));
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace inscribe
