// The broken-mesh corpus (support/broken_meshes.h) through the command line as users run it:
// each mesh written as an OFF file, then `info --repair auto`, `generate --repair auto` (an
// internal set) and `generate --cover --repair auto`, whose cover must hold every point sampled
// on the input's own triangles (brute force over the spheres, read back from the file); then
// one robot with a link per corpus mesh through `urdf --repair auto`, every link spherized.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
#include "support/broken_meshes.h"

namespace inscribe {
namespace {

namespace fs = std::filesystem;
using testing::BrokenMesh;
using testing::BrokenMeshCorpus;
using ::testing::HasSubstr;

// The mesh as an OFF file, triangles as given (broken ones included), 17 digits.
void WriteOff(const Mesh& mesh, const fs::path& path) {
  std::ofstream out(path);
  out.precision(17);
  out << "OFF\n" << mesh.num_vertices() << " " << mesh.num_triangles() << " 0\n";
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    out << mesh.vertices(v, 0) << " " << mesh.vertices(v, 1) << " " << mesh.vertices(v, 2) << "\n";
  }
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    out << "3 " << mesh.triangles(t, 0) << " " << mesh.triangles(t, 1) << " "
        << mesh.triangles(t, 2) << "\n";
  }
}

fs::path Dir() {
  static const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_corpus_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string FileName(const BrokenMesh& entry) { return entry.name + ".off"; }

class CliRepairCorpus : public ::testing::TestWithParam<int> {};

TEST_P(CliRepairCorpus, InfoGenerateAndCoverHoldTheInputTriangles) {
  const BrokenMesh entry = BrokenMeshCorpus()[static_cast<std::size_t>(GetParam())];
  SCOPED_TRACE(entry.name);
  const fs::path mesh = Dir() / FileName(entry);
  WriteOff(entry.mesh, mesh);
  const std::string m = Quote(mesh.string());

  const CliRun info = RunCli("info --json --repair auto " + m);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json report = nlohmann::json::parse(info.out);
  EXPECT_TRUE(report.at("usable").get<bool>());
  EXPECT_EQ(report.at("repair").at("wrapped").get<bool>(), entry.needs == MeshRepair::kWrap);
  if (entry.needs == MeshRepair::kFill || entry.needs == MeshRepair::kWrap) {
    // Never silent: the report says the solid is not the file's as given, and how.
    EXPECT_TRUE(report.at("repair").at("geometry_repaired").get<bool>());
    EXPECT_THAT(report.at("repair").at("repairs").get<std::string>(),
                HasSubstr(entry.needs == MeshRepair::kWrap ? "wrapped" : "filled"));
  }
  if (entry.needs == MeshRepair::kNone) EXPECT_EQ(RunCli("info " + m).exit_code, 0);

  const fs::path internal = Dir() / (entry.name + "_internal.json");
  const CliRun generated =
      RunCli("generate --repair auto --max-spheres 16 -o " + Quote(internal.string()) + " " + m);
  ASSERT_EQ(generated.exit_code, 0) << generated.err;
  absl::StatusOr<SphereFile> set = ReadSphereFile(internal.string());
  ASSERT_TRUE(set.ok()) << set.status();
  EXPECT_FALSE(set->set.spheres.empty());

  const fs::path cover = Dir() / (entry.name + "_cover.json");
  const CliRun covered = RunCli("generate --cover --repair auto --max-spheres 16 -o " +
                                Quote(cover.string()) + " " + m);
  ASSERT_EQ(covered.exit_code, 0) << covered.err;
  absl::StatusOr<SphereFile> file = ReadSphereFile(cover.string());
  ASSERT_TRUE(file.ok()) << file.status();
  bool certified = false;
  for (const auto& [name, value] : file->stats) {
    if (name == "certified") certified = std::get<bool>(value);
  }
  EXPECT_TRUE(certified);
  // Every point of the input's own triangles is held (the repaired solid contains them all:
  // filled holes add patches, a wrap encloses every triangle).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int missed = 0, sampled = 0;
  for (Eigen::Index t = 0; t < entry.mesh.num_triangles(); ++t) {
    const Vector3 a = entry.mesh.vertices.row(entry.mesh.triangles(t, 0)).transpose();
    const Vector3 b = entry.mesh.vertices.row(entry.mesh.triangles(t, 1)).transpose();
    const Vector3 c = entry.mesh.vertices.row(entry.mesh.triangles(t, 2)).transpose();
    for (int i = 0; i < 8; ++i) {
      double s = u(rng), r = u(rng);
      if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
      const Vector3 p = a + s * (b - a) + r * (c - a);
      bool held = false;
      for (const Sphere& sphere : file->set.spheres) {
        held = held || (p - sphere.center).norm() <= sphere.radius;
      }
      missed += !held;
      ++sampled;
    }
  }
  EXPECT_EQ(missed, 0) << "of " << sampled << " points of the input triangles";
}

INSTANTIATE_TEST_SUITE_P(Corpus, CliRepairCorpus,
                         ::testing::Range(0, static_cast<int>(BrokenMeshCorpus().size())),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return testing::BrokenMeshTestName(param.param);
                         });

// One robot, a link per corpus mesh (millimetre ones scaled by the URDF, as robots ship them):
// with --repair auto every link is spherized; with the default (safe) the links that need more
// are skipped, each saying which --repair makes it usable.
TEST(CliRepairCorpusRobot, EveryLinkIsSpherizedWithRepairAuto) {
  const std::vector<BrokenMesh> corpus = BrokenMeshCorpus();
  std::string links, joints;
  int needs_more = 0;
  for (std::size_t i = 0; i < corpus.size(); ++i) {
    const fs::path mesh = Dir() / FileName(corpus[i]);
    WriteOff(corpus[i].mesh, mesh);
    const bool millimetres = corpus[i].name.find("millimetres") != std::string::npos;
    links += "  <link name=\"" + corpus[i].name + "\"><collision><geometry><mesh filename=\"" +
             FileName(corpus[i]) + "\"" + (millimetres ? " scale=\"0.001 0.001 0.001\"" : "") +
             "/></geometry></collision></link>\n";
    if (i > 0) {
      joints += "  <joint name=\"j" + std::to_string(i) + "\" type=\"fixed\"><parent link=\"" +
                corpus[0].name + "\"/><child link=\"" + corpus[i].name + "\"/></joint>\n";
    }
    needs_more += corpus[i].needs == MeshRepair::kFill || corpus[i].needs == MeshRepair::kWrap;
  }
  const fs::path urdf = Dir() / "corpus.urdf";
  std::ofstream(urdf) << "<?xml version=\"1.0\"?>\n<robot name=\"corpus\">\n"
                      << links << joints << "</robot>\n";
  const std::string args = "urdf " + Quote(urdf.string()) + " --max-spheres-per-link 8 --json ";
  const CliRun all = RunCli(args + "--repair auto -o " + Quote((Dir() / "auto.urdf").string()));
  ASSERT_EQ(all.exit_code, 0) << all.err;
  const nlohmann::json report = nlohmann::json::parse(all.out);
  EXPECT_EQ(report.at("spherized").get<int>(), static_cast<int>(corpus.size()));

  const CliRun safe = RunCli(args + "-o " + Quote((Dir() / "safe.urdf").string()));
  EXPECT_EQ(safe.exit_code, 1) << safe.err;
  const nlohmann::json partial = nlohmann::json::parse(safe.out);
  EXPECT_EQ(partial.at("spherized").get<int>(), static_cast<int>(corpus.size()) - needs_more);
  for (const nlohmann::json& link : partial.at("links")) {
    if (link.at("status") == "skipped") {
      EXPECT_THAT(link.at("error").get<std::string>(), HasSubstr("--repair")) << link.dump();
    }
  }
}

}  // namespace
}  // namespace inscribe
