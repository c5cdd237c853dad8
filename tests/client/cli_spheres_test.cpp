// `inscribe generate` and `inscribe evaluate`, run as users run them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "client/cli_run.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string Eight() { return Quote(testing::TestMeshPath("eight.off")); }

fs::path TempDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_spheres_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

TEST(CliGenerate, JsonSummaryHasTheFiguresUsersNeed) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const CliRun run = RunCli("generate " + Eight() + " --max-spheres 120 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_LE(j.at("spheres").get<int>(), 120);
  EXPECT_GT(j.at("spheres").get<int>(), 90);
  EXPECT_GT(j.at("voxel_size").get<double>(), 0.0);
  EXPECT_GT(j.at("seconds").get<double>(), 0.0);
  const double mesh = j.at("volume_mesh").get<double>();
  const double ball_union = j.at("volume_union").get<double>();
  EXPECT_GT(ball_union, 0.0);
  EXPECT_LT(ball_union, mesh);
  EXPECT_NEAR(j.at("nerr").get<double>(), (mesh - ball_union) / mesh, 1e-12);
  EXPECT_EQ(j.at("nerr_kind"), "exact");
  EXPECT_EQ(j.at("protruding_spheres").get<int>(), 0);
  EXPECT_EQ(j.at("surface_samples").get<int>(), 100000);
  // The default spends the budget on the optimised selection: a pool, then a choice.
  EXPECT_EQ(j.at("selection"), "optimised");
  EXPECT_GT(j.at("pool_size").get<int>(), 120);
  EXPECT_GT(j.at("covered_fraction").get<double>(), 0.5);
  EXPECT_GE(j.at("search_runs").get<int>(), 1);
}

TEST(CliGenerate, SelectionPaperSearchesTheGridAndTheFileSaysWhich) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  double nerr[2] = {0.0, 0.0};
  int i = 0;
  for (const char* selection : {"paper", "optimised"}) {
    SCOPED_TRACE(selection);
    const CliRun run = RunCli("generate " + Eight() + " --max-spheres 120 --selection " +
                              selection + " --quality-samples 0");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j.at("params").at("selection"), selection);
    EXPECT_LE(j.at("spheres").size(), 120u);
    EXPECT_EQ(j.at("contacts").size(), j.at("spheres").size());
    const bool optimised = std::string(selection) == "optimised";
    EXPECT_EQ(j.at("stats").contains("pool_size"), optimised);
    if (!optimised) EXPECT_GT(j.at("stats").at("search_runs").get<int>(), 1);
    nerr[i++] = j.at("stats").at("nerr").get<double>();
  }
  EXPECT_LT(nerr[1], nerr[0]);
}

TEST(CliGenerate, DefaultOutputIsTheSphereSetJson) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const CliRun run = RunCli("generate " + Eight() + " --voxel-size 0.1");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("format"), "inscribe.spheres");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_THAT(j.at("mesh_sha256").get<std::string>(), HasSubstr("sha256:"));
  EXPECT_DOUBLE_EQ(j.at("params").at("voxel_size").get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(j.at("params").at("object_angle").get<double>(), 0.6);
  ASSERT_GT(j.at("spheres").size(), 10u);
  EXPECT_EQ(j.at("spheres").at(0).size(), 4u);
  EXPECT_EQ(j.at("contacts").size(), j.at("spheres").size());
  EXPECT_EQ(j.at("contacts").at(0).size(), 4u);
  EXPECT_TRUE(j.at("stats").contains("nerr"));
  EXPECT_TRUE(j.at("stats").contains("seconds"));
}

TEST(CliGenerate, EveryFormatIsWrittenAndReadableOnesEvaluateAlike) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  double nerr = -1.0;
  for (const char* extension : {"json", "sph", "csv", "obj", "yaml"}) {
    SCOPED_TRACE(extension);
    const fs::path out = dir / (std::string("eight.") + extension);
    const CliRun run =
        RunCli("generate " + Eight() + " --voxel-size 0.08 -o " + Quote(out.string()));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.out, "");  // the spheres went to the file
    ASSERT_TRUE(fs::exists(out));
    EXPECT_GT(fs::file_size(out), 100u);
    if (std::string(extension) == "obj") continue;
    const CliRun evaluated = RunCli("evaluate --json " + Eight() + " " + Quote(out.string()));
    ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
    const nlohmann::json j = nlohmann::json::parse(evaluated.out);
    EXPECT_EQ(j.at("nerr_kind"), "exact");
    // Every readable format keeps the spheres exactly, so the exact nerr is identical.
    if (nerr < 0) nerr = j.at("nerr").get<double>();
    EXPECT_EQ(j.at("nerr").get<double>(), nerr);
  }
  const CliRun text = RunCli("evaluate " + Eight() + " " + Quote((dir / "eight.json").string()));
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_THAT(text.out, HasSubstr("nerr (exact)"));
  EXPECT_THAT(text.out, HasSubstr("(sigma, theta)-fat"));
  fs::remove_all(dir);
}

TEST(CliEvaluate, ProtrudingSpheresFromAnotherToolGetABound) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const fs::path csv = dir / "big.csv";
  std::ofstream(csv) << "x,y,z,r\n0,0,0,0.5\n0.2,0.1,0,0.3\n";
  const CliRun run = RunCli("evaluate --json " + Eight() + " " + Quote(csv.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("nerr_kind"), "lower_bound");
  EXPECT_GT(j.at("protrusion_max").get<double>(), 0.0);
  fs::remove_all(dir);
}

// --certify on another tool's files: one ball around the whole mesh is a cover (exit 0, delta
// its reach); the internal spheres generate writes are not (exit 1, with a point they miss).
TEST(CliEvaluate, CertifyProvesACoverOrShowsAPointItMisses) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const fs::path ball = dir / "ball.csv";
  std::ofstream(ball) << "x,y,z,r\n0,0,0,10\n";
  CliRun run = RunCli("evaluate --certify --json " + Eight() + " " + Quote(ball.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j.at("certified").get<bool>());
  EXPECT_EQ(j.at("failed_cells"), 0);
  EXPECT_GT(j.at("delta").get<double>(), 9.0);
  EXPECT_FALSE(j.contains("uncovered_point"));

  const fs::path internal = dir / "internal.json";
  ASSERT_EQ(
      RunCli("generate " + Eight() + " --max-spheres 60 -o " + Quote(internal.string())).exit_code,
      0);
  run = RunCli("evaluate --certify " + Eight() + " " + Quote(internal.string()));
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_THAT(run.out, HasSubstr("NOT certified: the point ("));
  EXPECT_THAT(run.err, HasSubstr("is not a certified cover of"));
  run = RunCli("evaluate --certify --certify-resolution 0 " + Eight() + " " +
               Quote(internal.string()));
  EXPECT_EQ(run.exit_code, 64) << run.err;
  fs::remove_all(dir);
}

// --cover: a certified cover, whose file records its kind and certificate; evaluate --certify
// proves it again with the same delta.
TEST(CliGenerate, CoverIsCertifiedAndItsFileRecordsTheCertificate) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const fs::path path = dir / "cover.json";
  CliRun run =
      RunCli("generate " + Eight() + " --cover --max-spheres 60 --json -o " + Quote(path.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(run.out);
  EXPECT_EQ(summary.at("kind"), "cover");
  EXPECT_TRUE(summary.at("certified").get<bool>());
  EXPECT_EQ(summary.at("coverage").get<double>(), 1.0);
  EXPECT_FALSE(summary.contains("search_runs"));

  const nlohmann::json file = nlohmann::json::parse(std::ifstream(path));
  const nlohmann::json& params = file.at("params");
  const nlohmann::json& stats = file.at("stats");
  EXPECT_EQ(params.at("kind"), "cover");
  EXPECT_EQ(params.at("max_spheres"), 60);
  EXPECT_EQ(params.at("cover_resolution").get<double>(), 1.0 / 2048);
  EXPECT_FALSE(params.contains("epsilon"));  // the cover generator's own internal set
  EXPECT_TRUE(stats.at("certified").get<bool>());
  EXPECT_EQ(stats.at("delta"), summary.at("delta"));
  EXPECT_GT(stats.at("delta").get<double>(), 0.0);
  EXPECT_GT(stats.at("certificate_resolution").get<double>(), 0.0);
  EXPECT_GT(stats.at("certificate_cells").get<int>(), 0);
  EXPECT_EQ(stats.at("failed_cells"), 0);
  EXPECT_GE(stats.at("grown_spheres").get<int>(), 0);
  EXPECT_GE(stats.at("cover_candidates").get<int>(), 1);
  EXPECT_FALSE(file.contains("contacts"));
  EXPECT_LE(file.at("spheres").size(), 60u);

  run = RunCli("evaluate --certify --json " + Eight() + " " + Quote(path.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json certified = nlohmann::json::parse(run.out);
  EXPECT_TRUE(certified.at("certified").get<bool>());
  EXPECT_EQ(certified.at("delta"), stats.at("delta"));
  fs::remove_all(dir);
}

TEST(CliGenerate, BadOptionsAreClearErrorsNotHangs) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  struct Case {
    std::string args;
    int exit_code;
    std::string message;
  };
  const Case cases[] = {
      {"--voxel-size 0", 64, "voxel size must be a positive"},
      {"--voxel-size -2", 64, "voxel size must be a positive"},
      {"--voxel-size 1e-7", 64, "more than 20000000 voxels"},
      {"--voxel-size 0.01 --max-voxels 1000", 64, "more than 1000 voxels"},
      {"--object-angle 3.5", 64, "object angle must lie in (0, pi)"},
      {"--object-angle 0", 64, "object angle"},
      {"--max-spheres 0", 64, "at least 1"},
      {"--samples 1", 64, "samples per voxel"},
      {"--voxel-size 0.1 --max-spheres 10", 64, "excludes"},
      {"--format pdf", 64, "pdf"},
      {"--cover --voxel-size 0.1", 64, "excludes"},
      {"--cover --dilate", 64, "excludes"},
      {"--max-protrusion 0.1", 64, "requires"},
      {"--cover-resolution 0.01", 64, "requires"},
      {"--cover --max-spheres 10 --max-protrusion 0.1", 64, "excludes"},
      {"--cover --max-protrusion -1", 64, "max_protrusion must be a finite length > 0"},
      {"--cover --cover-resolution 0", 64, "resolution"},
      {"--cover --object-angle 0.5", 64, "excludes"},
      {"--cover --subdivide-boundary", 64, "excludes"},
      {"--selection greedy", 64, "unknown sphere selection 'greedy'"},
      {"--voxel-size 0.1 --selection paper", 64, "excludes"},
      {"--cover --selection paper", 64, "excludes"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CliRun run = RunCli("generate " + Eight() + " " + c.args);
    EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message));
    EXPECT_EQ(run.out, "");
  }
}

TEST(CliGenerate, UnusableMeshesAndFilesAreNamed) {
  INSCRIBE_REQUIRE_MESH("pig.off");
  CliRun run = RunCli("generate " + Quote(testing::TestMeshPath("pig.off")));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.err, HasSubstr("not closed: 55 border edges"));
  run = RunCli("generate /nonexistent/mesh.off");
  EXPECT_EQ(run.exit_code, 2);
  const fs::path dir = TempDir();
  const fs::path garbage = dir / "garbage.json";
  std::ofstream(garbage) << "{\"format\": \"inscribe.spheres\", \"version\": 1, \"spheres\": [[1,2";
  run = RunCli("evaluate " + Eight() + " " + Quote(garbage.string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("garbage.json"));
  fs::remove_all(dir);
}

TEST(CliGenerate, DilateGrowsTheSpheresAndReportsABound) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const std::string base = "generate " + Eight() + " --voxel-size 0.08 --subdivide-boundary ";
  const fs::path plain_path = dir / "plain.json";
  const fs::path dilated_path = dir / "dilated.json";
  ASSERT_EQ(RunCli(base + "-o " + Quote(plain_path.string())).exit_code, 0);
  const CliRun run = RunCli(base + "--dilate --json -o " + Quote(dilated_path.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(run.out);
  EXPECT_EQ(summary.at("kind"), "dilated");
  EXPECT_EQ(summary.at("nerr_kind"), "lower_bound");
  EXPECT_GT(summary.at("v_points").get<int>(), 100);
  EXPECT_GT(summary.at("grown").get<int>(), 100);
  EXPECT_GT(summary.at("dilation_seconds").get<double>(), 0.0);

  const nlohmann::json plain = nlohmann::json::parse(std::ifstream(plain_path));
  const nlohmann::json dilated = nlohmann::json::parse(std::ifstream(dilated_path));
  EXPECT_EQ(plain.at("params").at("kind"), "internal");
  EXPECT_EQ(dilated.at("params").at("kind"), "dilated");
  EXPECT_FALSE(dilated.contains("contacts"));
  EXPECT_FALSE(dilated.at("stats").at("nerr_is_exact").get<bool>());
  EXPECT_GT(dilated.at("stats").at("coverage").get<double>(),
            plain.at("stats").at("coverage").get<double>());
  // Same spheres, same order, same centres; radii never smaller, grown by max_growth at most.
  ASSERT_EQ(dilated.at("spheres").size(), plain.at("spheres").size());
  double max_growth = 0.0;
  int grown = 0;
  for (std::size_t s = 0; s < plain.at("spheres").size(); ++s) {
    const auto& a = plain.at("spheres").at(s);
    const auto& b = dilated.at("spheres").at(s);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.at(k).get<double>(), b.at(k).get<double>());
    const double growth = b.at(3).get<double>() - a.at(3).get<double>();
    EXPECT_GE(growth, 0.0);
    grown += growth > 0.0;
    max_growth = std::max(max_growth, growth);
  }
  EXPECT_EQ(dilated.at("stats").at("grown").get<int>(), grown);
  EXPECT_EQ(dilated.at("stats").at("max_growth").get<double>(), max_growth);

  const CliRun evaluated =
      RunCli("evaluate --json " + Eight() + " " + Quote(dilated_path.string()));
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  EXPECT_EQ(nlohmann::json::parse(evaluated.out).at("nerr_kind"), "lower_bound");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace inscribe
