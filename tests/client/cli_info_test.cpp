// Runs the real `inscribe` binary, as users do, and checks its output and exit status.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <assimp/Exporter.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "client/cli_run.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/assimp_scenes.h"
#include "support/cgal_mesh_writer.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST(CliInfo, JsonOnARealMesh) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const CliRun run = RunCli("info --json " + Quote(testing::TestMeshPath("eight.off")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(
      std::regex_match(j.at("mesh_sha256").get<std::string>(), std::regex("sha256:[0-9a-f]{64}")));
  EXPECT_EQ(j.at("vertices").get<int>(), 315);  // header of eight.off: 315 634 0
  EXPECT_EQ(j.at("triangles").get<int>(), 634);
  EXPECT_TRUE(j.at("closed").get<bool>());
  EXPECT_TRUE(j.at("usable").get<bool>());
  EXPECT_GT(j.at("volume").get<double>(), 0.0);
  EXPECT_EQ(j.at("bbox").at("min").size(), 3u);
  EXPECT_EQ(j.at("bbox").at("max").size(), 3u);
  // Exactly one line of JSON.
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1);
}

TEST(CliInfo, TextReport) {
  INSCRIBE_REQUIRE_MESH("cow.off");
  const CliRun run = RunCli("info " + Quote(testing::TestMeshPath("cow.off")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("sha256:"));
  EXPECT_THAT(run.out, HasSubstr("self-intersections"));
  EXPECT_THAT(run.out, HasSubstr("verdict              usable"));
}

TEST(CliInfo, HashIsStableAcrossRuns) {
  INSCRIBE_REQUIRE_MESH("knot1.off");
  const std::string args = "info --json " + Quote(testing::TestMeshPath("knot1.off"));
  const auto a = nlohmann::json::parse(RunCli(args).out);
  const auto b = nlohmann::json::parse(RunCli(args).out);
  EXPECT_EQ(a.at("mesh_sha256"), b.at("mesh_sha256"));
}

TEST(CliInfo, OpenMeshFailsWithOneLineReason) {
  INSCRIBE_REQUIRE_MESH("ChineseDragon-10kv.off");
  const CliRun run =
      RunCli("info --json " + Quote(testing::TestMeshPath("ChineseDragon-10kv.off")));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.err, HasSubstr("mesh is not closed: 6 border edges"));
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1);
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j.at("closed").get<bool>());
  EXPECT_FALSE(j.at("usable").get<bool>());
}

TEST(CliInfo, FillHolesMakesTheOpenPigUsable) {
  INSCRIBE_REQUIRE_MESH("pig.off");
  const std::string pig = Quote(testing::TestMeshPath("pig.off"));
  const CliRun open = RunCli("info --json " + pig);
  EXPECT_EQ(open.exit_code, 1);
  const CliRun run = RunCli("info --json --fill-holes " + pig);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j.at("closed").get<bool>());
  EXPECT_TRUE(j.at("usable").get<bool>());
  EXPECT_EQ(j.at("triangles").get<int>(), 891);  // as given
  EXPECT_EQ(j.at("counts").at("border_edges").get<int>(), 55);
  EXPECT_EQ(j.at("repair").at("holes_filled").get<int>(), 7);
  EXPECT_EQ(j.at("repair").at("hole_triangles_added").get<int>(), 41);
  EXPECT_GT(j.at("volume").get<double>(), 0.0);
  bool reported = false;
  for (const auto& issue : j.at("issues")) {
    if (issue.at("code") == "holes_filled") {
      EXPECT_EQ(issue.at("severity"), "fixed");
      EXPECT_EQ(issue.at("message"), "filled 7 holes (55 border edges) with 41 triangles");
      reported = true;
    }
  }
  EXPECT_TRUE(reported) << run.out;
  // The hash is the repaired mesh's, not the file's.
  EXPECT_NE(j.at("mesh_sha256"), nlohmann::json::parse(open.out).at("mesh_sha256"));
  EXPECT_THAT(RunCli("info --fill-holes " + pig).out,
              HasSubstr("triangles            891 + 41 filling 7 holes"));
}

TEST(CliInfo, BadFilesFailWithOneLineReason) {
  const fs::path dir = fs::temp_directory_path() / ("inscribe_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  struct Case {
    std::string name, contents, expected;
  };
  const std::vector<Case> cases = {
      {"empty.off", "", "file is empty"},
      {"cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1", "coordinates, expected 3"},
      {"index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "refers to vertex 3"},
      {"nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "not a finite number"},
      {"text.off", "just some words\n", "expected the OFF header"},
      {"notes.txt", "OFF\n", "unsupported mesh format"},
  };
  for (const Case& c : cases) {
    std::ofstream(dir / c.name) << c.contents;
    const CliRun run = RunCli("info " + Quote((dir / c.name).string()));
    EXPECT_EQ(run.exit_code, 2) << c.name;
    EXPECT_THAT(run.err, HasSubstr(c.expected)) << c.name;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << c.name << ": " << run.err;
    EXPECT_EQ(run.out, "") << c.name;
  }
  const CliRun missing = RunCli("info " + Quote((dir / "missing.off").string()));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("no such file"));
  fs::remove_all(dir);
}

// An OBJ as MeshLab writes it, each vertex repeated per face: welded, it is eight.off again,
// and info says so.
TEST(CliInfo, RepeatedVerticesAreWeldedAndReported) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_weld_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  absl::StatusOr<Mesh> eight = ReadMesh(testing::TestMeshPath("eight.off"));
  ASSERT_TRUE(eight.ok()) << eight.status();
  const std::string obj = (dir / "eight_per_face.obj").string();
  ASSERT_TRUE(testing::WriteMeshWithCgal(obj, testing::PerFaceVertices(*eight), false));

  const CliRun run = RunCli("info --json " + Quote(obj));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("vertices").get<int>(), 3 * 634);  // as given
  EXPECT_EQ(j.at("counts").at("welded_vertices").get<int>(), 3 * 634 - 315);
  EXPECT_EQ(j.at("counts").at("weld_collapsed_triangles").get<int>(), 0);
  EXPECT_TRUE(j.at("closed").get<bool>());
  const nlohmann::json original =
      nlohmann::json::parse(RunCli("info --json " + Quote(testing::TestMeshPath("eight.off"))).out);
  EXPECT_DOUBLE_EQ(j.at("volume").get<double>(), original.at("volume").get<double>());
  bool reported = false;
  for (const auto& issue : j.at("issues")) {
    if (issue.at("code") == "welded_vertices") {
      EXPECT_EQ(issue.at("severity"), "fixed");
      EXPECT_EQ(issue.at("count").get<int>(), 3 * 634 - 315);
      EXPECT_THAT(issue.at("message").get<std::string>(), HasSubstr("welded 1587 vertices"));
      reported = true;
    }
  }
  EXPECT_TRUE(reported) << run.out;
  const CliRun text = RunCli("info " + Quote(obj));
  EXPECT_THAT(text.out, HasSubstr("vertices             1902 (1587 welded: 315 left)"));
  EXPECT_THAT(text.out, HasSubstr("fixed    welded 1587 vertices at identical positions"));

  // Copies up to 2e-9 apart: welded as cracks by the default --repair safe; with --repair none
  // refused with a hint; welded with --weld-tolerance.
  Mesh near = testing::PerFaceVertices(*eight);
  for (Eigen::Index v = 0; v < near.num_vertices(); ++v) {
    near.vertices(v, 0) += 1e-12 * static_cast<double>(v + 1);  // every copy apart, < 2e-9
  }
  const std::string near_obj = (dir / "eight_near.obj").string();
  ASSERT_TRUE(testing::WriteMeshWithCgal(near_obj, near, false));
  const CliRun safe = RunCli("info --json " + Quote(near_obj));
  ASSERT_EQ(safe.exit_code, 0) << safe.err;
  EXPECT_EQ(nlohmann::json::parse(safe.out).at("repair").at("crack_vertices_welded").get<int>(),
            3 * 634 - 315);
  const CliRun refused = RunCli("info --repair none " + Quote(near_obj));
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.err, HasSubstr("--repair safe welds those within 1e-4 of the size"));
  const CliRun welded = RunCli("info --json --weld-tolerance 1e-6 " + Quote(near_obj));
  ASSERT_EQ(welded.exit_code, 0) << welded.err;
  EXPECT_EQ(nlohmann::json::parse(welded.out).at("counts").at("welded_vertices").get<int>(),
            3 * 634 - 315);
  EXPECT_NE(RunCli("info --weld-tolerance -1 " + Quote(near_obj)).exit_code, 0);
  fs::remove_all(dir);
}

TEST(CliInfo, ColladaAndGltfFiles) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_scene_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Eigen::Matrix4d lifted = Eigen::Matrix4d::Identity();
  lifted(2, 3) = 5.0;
  const std::unique_ptr<aiScene> scene =
      testing::MakeScene({testing::LoadTestMesh("eight.off")}, {{0, lifted}});
  for (const auto& [format_id, name] :
       {std::pair{"collada", "eight.dae"}, std::pair{"glb2", "eight.glb"}}) {
    const std::string path = (dir / name).string();
    Assimp::Exporter exporter;
    ASSERT_EQ(exporter.Export(scene.get(), format_id, path), AI_SUCCESS)
        << exporter.GetErrorString();
    const CliRun run = RunCli("info --json " + Quote(path));
    ASSERT_EQ(run.exit_code, 0) << name << ": " << run.err;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j.at("triangles").get<int>(), 634) << name;
    EXPECT_TRUE(j.at("usable").get<bool>()) << name;
    EXPECT_NEAR(j.at("bbox").at("min")[2].get<double>(),
                5.0 + testing::LoadTestMesh("eight.off").vertices.col(2).minCoeff(), 1e-5)
        << name;
  }
  std::ofstream(dir / "garbage.glb") << "glTF but not really";
  const CliRun garbage = RunCli("info " + Quote((dir / "garbage.glb").string()));
  EXPECT_EQ(garbage.exit_code, 2);
  EXPECT_THAT(garbage.err, HasSubstr("garbage.glb: not a readable binary glTF file"));
  EXPECT_EQ(std::count(garbage.err.begin(), garbage.err.end(), '\n'), 1) << garbage.err;
  fs::remove_all(dir);
}

TEST(CliInfo, UsageErrors) {
  EXPECT_NE(RunCli("").exit_code, 0);
  EXPECT_NE(RunCli("info").exit_code, 0);
  EXPECT_NE(RunCli("frobnicate x.off").exit_code, 0);
  EXPECT_EQ(RunCli("--help").exit_code, 0);
}

}  // namespace
}  // namespace inscribe
