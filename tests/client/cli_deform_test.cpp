// `inscribe deform`, run as users run it: on a deformed copy of a demo mesh written to disk.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "client/cli_run.h"
#include "deformation_sequences.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using sequences::DeformationKind;

// A temporary directory holding eight.off as read, its spheres, and deformed copies.
class CliDeform : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::TestMeshPath("eight.off").empty()) {
      GTEST_SKIP() << "eight.off is missing; run scripts/fetch-meshes";
    }
    dir_ = fs::temp_directory_path() / ("inscribe_cli_deform_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    absl::StatusOr<Mesh> mesh = ReadMesh(testing::TestMeshPath("eight.off"));
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    reference_ = *std::move(mesh);
    reference_path_ = (dir_ / "eight.off").string();
    ASSERT_TRUE(WriteMesh(reference_path_, reference_).ok());
    spheres_path_ = (dir_ / "eight.json").string();
    const CliRun run = RunCli("generate " + Quote(reference_path_) + " --max-spheres 150 -o " +
                              Quote(spheres_path_));
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::string WriteFrame(const std::string& name, const Mesh& mesh) {
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(WriteMesh(path, mesh).ok());
    return path;
  }
  std::string Deformed(DeformationKind kind, double t) {
    return WriteFrame(std::string(sequences::DeformationKindName(kind)) + ".off",
                      Mesh{sequences::Deform(reference_.vertices, kind, t), reference_.triangles});
  }
  CliRun Deform(const std::string& deformed, const std::string& extra = "") {
    return RunCli("deform " + Quote(reference_path_) + " " + Quote(spheres_path_) + " " +
                  Quote(deformed) + " " + extra);
  }

  fs::path dir_;
  Mesh reference_;
  std::string reference_path_, spheres_path_;
};

TEST_F(CliDeform, JsonSummaryHasTheFiguresUsersNeed) {
  const CliRun run = Deform(Deformed(DeformationKind::kTwist, 1.0), "--json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_GT(j.at("spheres").get<int>(), 100);
  EXPECT_EQ(j.at("spheres"), j.at("reference_spheres"));
  EXPECT_GT(j.at("seconds").get<double>(), 0.0);
  EXPECT_GT(j.at("bounds_seconds").get<double>(), 0.0);
  const double lower = j.at("nerr_lower").get<double>();
  const double upper = j.at("nerr_upper").get<double>();
  EXPECT_GT(lower, 0.0);
  EXPECT_LE(lower, upper);
  EXPECT_LE(upper, j.at("nerr_upper_uniform_xi").get<double>());
  const double xi = j.at("xi").get<double>();
  EXPECT_GT(xi, 0.0);
  EXPECT_LT(j.at("max_protrusion").get<double>(), xi);
  EXPECT_FALSE(j.at("nerr_is_exact").get<bool>());
  EXPECT_THAT(j.at("mesh_sha256").get<std::string>(), HasSubstr("sha256:"));
  EXPECT_NE(j.at("mesh_sha256"), j.at("reference_mesh_sha256"));
}

TEST_F(CliDeform, StrictWritesInternalTangentSpheresWithExactError) {
  const std::string out = (dir_ / "strict.json").string();
  const CliRun run =
      Deform(Deformed(DeformationKind::kPinch, 1.0), "--strict --xi 0.001 --json -o " + Quote(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j.at("nerr_is_exact").get<bool>());
  EXPECT_EQ(j.at("nerr_lower"), j.at("nerr_upper"));
  EXPECT_LE(j.at("max_protrusion").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j.at("xi").get<double>(), 0.001);
  // The file is a reference for `evaluate` on the deformed mesh: exact nerr, nothing sticks out.
  const CliRun evaluate =
      RunCli("evaluate " + Quote((dir_ / "pinch.off").string()) + " " + Quote(out) + " --json");
  ASSERT_EQ(evaluate.exit_code, 0) << evaluate.err;
  const nlohmann::json e = nlohmann::json::parse(evaluate.out);
  EXPECT_EQ(e.at("protruding_spheres").get<int>(), 0);
  EXPECT_NEAR(e.at("nerr").get<double>(), j.at("nerr_lower").get<double>(), 1e-12);
  EXPECT_EQ(e.at("mesh_sha256"), j.at("mesh_sha256"));
}

TEST_F(CliDeform, RigidMotionMovesTheFileExactly) {
  const std::string out = (dir_ / "rigid.json").string();
  const CliRun run = Deform(Deformed(DeformationKind::kRigid, 1.0), "-o " + Quote(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("nerr"));  // the text summary
  absl::StatusOr<SphereFile> before = ReadSphereFile(spheres_path_);
  absl::StatusOr<SphereFile> after = ReadSphereFile(out);
  ASSERT_TRUE(before.ok() && after.ok());
  ASSERT_EQ(after->set.size(), before->set.size());
  EXPECT_EQ(after->set.contacts.size(), after->set.size());
  // The rigid map of DeformationKind::kRigid, applied to the centres.
  Vertices centres(static_cast<Eigen::Index>(before->set.size()), 3);
  for (std::size_t i = 0; i < before->set.size(); ++i) {
    centres.row(static_cast<Eigen::Index>(i)) = before->set.spheres[i].center.transpose();
  }
  // Deform's frame comes from the reference's bounding box: move the centres with the mesh.
  Vertices stacked(reference_.num_vertices() + centres.rows(), 3);
  stacked << reference_.vertices, centres;
  const Vertices moved = sequences::Deform(stacked, DeformationKind::kRigid, 1.0);
  // Appending the centres (inside the mesh) does not change the bounding box.
  for (std::size_t i = 0; i < before->set.size(); ++i) {
    const Vector3 expected = moved.row(reference_.num_vertices() + static_cast<Eigen::Index>(i));
    EXPECT_LE((after->set.spheres[i].center - expected).norm(), 1e-9) << "sphere " << i;
    EXPECT_NEAR(after->set.spheres[i].radius, before->set.spheres[i].radius, 1e-9);
  }
}

TEST_F(CliDeform, RefusesMeshesWhoseTrianglesDiffer) {
  Mesh swapped{sequences::Deform(reference_.vertices, DeformationKind::kTwist, 0.5),
               reference_.triangles};
  std::swap(swapped.triangles(5, 0), swapped.triangles(5, 1));
  CliRun run = Deform(WriteFrame("swapped.off", swapped), "--json");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("is not a deformation of"));
  EXPECT_THAT(run.err, HasSubstr("triangle 5 is"));
  EXPECT_TRUE(run.out.empty());

  Mesh fewer{reference_.vertices, reference_.triangles.topRows(reference_.num_triangles() - 2)};
  run = Deform(WriteFrame("fewer.off", fewer));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr(std::to_string(reference_.num_triangles() - 2) + " triangles"));

  Mesh more_vertices{Vertices(reference_.num_vertices() + 1, 3), reference_.triangles};
  more_vertices.vertices << reference_.vertices, Eigen::RowVector3d(9, 9, 9);
  run = Deform(WriteFrame("more.off", more_vertices));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("vertices; the reference has"));
}

TEST_F(CliDeform, RefusesWrongSpheresAndInvertedMeshes) {
  const std::string twisted = Deformed(DeformationKind::kTwist, 0.5);
  // No contacts: a CSV file holds spheres only.
  const std::string csv = (dir_ / "eight.csv").string();
  ASSERT_EQ(
      RunCli("generate " + Quote(reference_path_) + " --voxel-size 0.1 -o " + Quote(csv)).exit_code,
      0);
  CliRun run = RunCli("deform " + Quote(reference_path_) + " " + Quote(csv) + " " + Quote(twisted));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("no contact points"));

  // Spheres made for another mesh.
  run = RunCli("deform " + Quote(twisted) + " " + Quote(spheres_path_) + " " + Quote(twisted));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("was made for mesh"));

  // A mirror image is inside out.
  Mesh mirrored = reference_;
  mirrored.vertices.col(0) *= -1.0;
  run = Deform(WriteFrame("mirrored.off", mirrored));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.err, HasSubstr("inverts"));

  run = Deform((dir_ / "missing.off").string());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("missing.off"));

  EXPECT_EQ(Deform(twisted, "--xi -1").exit_code, 64);
  EXPECT_EQ(RunCli("deform " + Quote(reference_path_)).exit_code, 64);
}

}  // namespace
}  // namespace inscribe
