#include "inscribe/mesh/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <random>

#include "inscribe/solid/mesh_validation.h"
#include "support/cgal_mesh_writer.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

namespace fs = std::filesystem;

class MeshFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("inscribe_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& bytes) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }

  // Writes `mesh` with CGAL's writer (an independent path from our reader's caller).
  std::string WriteWithCgal(const std::string& name, const Mesh& mesh, bool binary) {
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(testing::WriteMeshWithCgal(path, mesh, binary));
    return path;
  }

  fs::path dir_;
};

TEST_F(MeshFileTest, ReadsEveryFormatBack) {
  const Mesh sphere = testing::Icosphere(2, Vector3(0.5, -1, 2), 1.5);
  const double expected_volume = SignedVolume(sphere);
  for (const auto& [name, binary] :
       std::vector<std::pair<std::string, bool>>{{"a.off", false},
                                                 {"a.obj", false},
                                                 {"a.stl", false},
                                                 {"b.stl", true},
                                                 {"a.ply", false},
                                                 {"b.ply", true},
                                                 {"UPPER.OFF", false}}) {
    SCOPED_TRACE(name);
    const std::string path = WriteWithCgal(name, sphere, binary);
    absl::StatusOr<Mesh> mesh = ReadMesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->num_triangles(), sphere.num_triangles());
    absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(mesh));
    ASSERT_TRUE(prepared.ok()) << prepared.status();
    // Binary STL stores single precision.
    EXPECT_NEAR(prepared->report.volume, expected_volume, binary ? 1e-5 : 1e-12);
  }
}

// WriteMesh then ReadMesh gives back the same doubles and triangles (OFF, OBJ, PLY; STL has
// no shared vertices, so only the solid is compared), with random coordinates that need all
// 17 digits.
TEST_F(MeshFileTest, WriteMeshRoundTripsExactly) {
  Mesh mesh = testing::Icosphere(2, Vector3(0.5, -1, 2), 1.5);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) mesh.vertices(v, k) += jitter(rng) / 3.0;
  }
  for (const std::string name : {"w.off", "w.obj", "w.ply", "W.OFF", "w.stl"}) {
    SCOPED_TRACE(name);
    const std::string path = (dir_ / name).string();
    ASSERT_TRUE(WriteMesh(path, mesh).ok());
    absl::StatusOr<Mesh> back = ReadMesh(path);
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->num_triangles(), mesh.num_triangles());
    if (name == "w.stl") {
      EXPECT_NEAR(SignedVolume(*back), SignedVolume(mesh), 1e-12);
      continue;
    }
    EXPECT_EQ(back->vertices, mesh.vertices);
    EXPECT_EQ(back->triangles, mesh.triangles);
  }
  // Writing again replaces the file whole.
  const std::string path = (dir_ / "w.off").string();
  ASSERT_TRUE(WriteMesh(path, testing::UnitCube()).ok());
  absl::StatusOr<Mesh> cube = ReadMesh(path);
  ASSERT_TRUE(cube.ok());
  EXPECT_EQ(cube->num_triangles(), 12);
}

TEST_F(MeshFileTest, WriteMeshRefusesBadInput) {
  const Mesh cube = testing::UnitCube();
  absl::Status s = WriteMesh((dir_ / "a.xyz").string(), cube);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("'.xyz'"));
  Mesh nan = cube;
  nan.vertices(2, 1) = std::nan("");
  s = WriteMesh((dir_ / "nan.off").string(), nan);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("non-finite"));
  Mesh bad_index = cube;
  bad_index.triangles(3, 2) = 99;
  s = WriteMesh((dir_ / "idx.off").string(), bad_index);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(dir_ / "idx.off"));
  s = WriteMesh((dir_ / "no" / "such" / "dir.off").string(), cube);
  EXPECT_EQ(s.code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(s.message()), HasSubstr("dir.off"));
}

TEST_F(MeshFileTest, TriangulatesPolygons) {
  // A cube of quads, one face given as a non-convex hexagon... of the same square.
  const std::string path = Write("quads.off",
                                 "OFF\n8 6 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n"
                                 "1 1 1\n4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n"
                                 "4 1 3 7 5\n");
  ReadMeshInfo info;
  absl::StatusOr<Mesh> mesh = ReadMesh(path, &info);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(info.polygons, 6);
  EXPECT_EQ(info.polygons_triangulated, 6);
  EXPECT_EQ(mesh->num_triangles(), 12);
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(mesh));
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  EXPECT_NEAR(prepared->report.volume, 1.0, 1e-15);
}

TEST_F(MeshFileTest, CgalQuadCube) {
  INSCRIBE_REQUIRE_MESH("cube_quad.off");
  absl::StatusOr<Mesh> mesh = ReadMesh(testing::TestMeshPath("cube_quad.off"));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(mesh));
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  EXPECT_GT(prepared->report.volume, 0.0);
}

// The bad inputs of the foundation issue: each a clear error naming the problem.

TEST_F(MeshFileTest, ChineseDragonIsNotClosed) {
  INSCRIBE_REQUIRE_MESH("ChineseDragon-10kv.off");
  absl::StatusOr<Mesh> mesh = ReadMesh(testing::TestMeshPath("ChineseDragon-10kv.off"));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(mesh));
  ASSERT_FALSE(prepared.ok());
  EXPECT_EQ(prepared.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(prepared.status().message(),
              AllOf(HasSubstr("not closed"), HasSubstr("6 border edges")));
}

TEST_F(MeshFileTest, EmptyFile) {
  for (const char* name : {"empty.off", "empty.obj", "empty.stl", "empty.ply"}) {
    absl::StatusOr<Mesh> mesh = ReadMesh(Write(name, ""));
    ASSERT_FALSE(mesh.ok()) << name;
    EXPECT_THAT(mesh.status().message(), HasSubstr("file is empty")) << name;
  }
}

TEST_F(MeshFileTest, TruncatedObj) {
  const std::string whole = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
  // Cut inside a vertex line and inside a face line.
  absl::StatusOr<Mesh> cut_vertex = ReadMesh(Write("v.obj", whole.substr(0, 20)));
  ASSERT_FALSE(cut_vertex.ok());
  EXPECT_THAT(cut_vertex.status().message(),
              AllOf(HasSubstr("line 3"), HasSubstr("coordinates, expected 3")));
  absl::StatusOr<Mesh> cut_face = ReadMesh(Write("f.obj", whole.substr(0, whole.size() - 3)));
  ASSERT_FALSE(cut_face.ok());
  EXPECT_THAT(std::string(cut_face.status().message()), HasSubstr("face 2 has 2 corners"));
  // Whole faces missing: the file parses, and validation says the surface is open.
  absl::StatusOr<Mesh> missing_face = ReadMesh(Write("m.obj", whole));
  ASSERT_TRUE(missing_face.ok()) << missing_face.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(missing_face));
  ASSERT_FALSE(prepared.ok());
  EXPECT_THAT(prepared.status().message(), HasSubstr("not closed: 3 border edges"));
}

TEST_F(MeshFileTest, TruncatedOff) {
  absl::StatusOr<Mesh> mesh =
      ReadMesh(Write("t.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.status().message(), HasSubstr("file ends after 2 of 4 faces"));
}

TEST_F(MeshFileTest, HeaderCountsBeyondTheFile) {
  // CGAL would reserve memory for a billion vertices before noticing the file is short.
  absl::StatusOr<Mesh> huge = ReadMesh(Write("h.off", "OFF\n1000000000 1000000000 0\n0 0 0\n"));
  ASSERT_FALSE(huge.ok());
  EXPECT_THAT(std::string(huge.status().message()),
              HasSubstr("file ends after 1 of 1000000000 vertices (truncated?)"));
  absl::StatusOr<Mesh> same_line = ReadMesh(Write("s.off", "OFF 99 99 0\n"));
  ASSERT_FALSE(same_line.ok());
  EXPECT_THAT(std::string(same_line.status().message()),
              HasSubstr("file ends after 0 of 99 vertices"));
  absl::StatusOr<Mesh> negative = ReadMesh(Write("n.off", "# made by hand\nOFF\n-4 4 0\n"));
  ASSERT_FALSE(negative.ok());
  EXPECT_THAT(std::string(negative.status().message()),
              HasSubstr("line 3: header announces -4 vertices and 4 faces; counts cannot be "
                        "negative"));
}

TEST_F(MeshFileTest, HostileCountsAreRefusedBeforeCgalSizesArrays) {
  struct Case {
    std::string name, bytes, expected;
  };
  std::string binary_ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list int int vertex_indices\nend_header\n";
  binary_ply += std::string(36, '\0');
  binary_ply += std::string("\x00\xca\x9a\x3b", 4);  // a face of 10^9 corners
  binary_ply += std::string(12, '\0');
  const std::vector<Case> cases = {
      {"corners.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n999999999 0 1 2\n",
       "line 6: face 0 announces 999999999 corners but lists 3"},
      {"binary.off", "OFF BINARY\n", "binary OFF is not supported"},
      // CGAL 5.5 crashed on this one (found by MeshIoMutation).
      {"orphan.ply", "ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n1\n",
       "line 3: property before any element"},
      {"list.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n",
       "face 0: a list of 1000000000 items is longer than the rest of the file"},
      {"binary.ply", binary_ply,
       "face 0: a list of 1000000000 items is longer than the rest of the file"},
      {"noformat.ply", "ply\nelement vertex 1\nproperty float x\nend_header\n",
       "header has no format line"},
      // CGAL 5.5 called through a null pointer (UBSan, found by fuzz_mesh).
      {"ushort.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property uint16 z\nelement face 1\nproperty list uchar int vertex_indices\n"
       "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "line 6: vertex coordinate z has type uint16; expected float or double"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<Mesh> mesh = ReadMesh(Write(c.name, c.bytes));
    ASSERT_FALSE(mesh.ok()) << c.name;
    EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(c.expected)) << c.name;
  }
  // The same layouts with honest counts still read.
  absl::StatusOr<Mesh> honest = ReadMesh(
      Write("honest.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 4\nproperty list int int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
  ASSERT_TRUE(honest.ok()) << honest.status();
  EXPECT_EQ(honest->num_triangles(), 4);
}

// Found by fuzz_mesh (tests/fuzz): CGAL reads OFF counts with `>>` across lines and corner
// counts as the record's first number ("442949672=6" is 442949672, "4.4e8" is 440000000), and
// a count line may go on with the first vertex. Each file below made CGAL allocate gigabytes
// (the first was OOM-killed at 147 bytes) while the line-by-line pre-check passed it.
TEST_F(MeshFileTest, OffCountsAreReadAsCgalReadsThem) {
  struct Case {
    std::string name, bytes, expected;
  };
  const std::vector<Case> cases = {
      {"glued.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n442949672=6 0 1 2\n",
       "line 6: face 0 announces 442949672 corners but lists 0"},
      {"float.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4.4e8 0 1 2\n",
       "line 6: face 0 announces 440000000 corners but lists 3"},
      {"shifted.off", "OFF\n2 1 0 0 0 0\n0 0 0\n1000000000 0 1\n",
       "line 4: face 0 announces 1000000000 corners but lists 2"},
      // CGAL casts each corner to size_t: undefined behaviour for -1 (UBSan under fuzz_mesh).
      {"negative.off", "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3-1 2\n",
       "line 9: face 2 refers to vertex -1, but the file has 4 vertices"},
      // Refused by the pre-check; the message is the line-by-line diagnosis's.
      {"split.off", "OFF\n# counts one per line\n1000000000\n1\n0\n0 0 0\n",
       "not a valid off file: line 3"},
      {"padded.off", "OFF\n0000000000001000000000 1 0\n0 0 0\n", "1000000000 vertices"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<Mesh> mesh = ReadMesh(Write(c.name, c.bytes));
    ASSERT_FALSE(mesh.ok()) << c.name;
    EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(c.expected)) << c.name;
  }
  // Counts split over lines, a count line going on with the first vertex, and padded counts
  // are honest OFF to CGAL, and still read.
  const std::vector<std::string> honest = {
      "OFF\n4\n4\n0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
      "OFF 4 4 0 0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
      "OFF\n004 04 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"};
  for (const std::string& bytes : honest) {
    absl::StatusOr<Mesh> mesh = ReadMesh(Write("honest.off", bytes));
    ASSERT_TRUE(mesh.ok()) << bytes << ": " << mesh.status();
    EXPECT_EQ(mesh->num_vertices(), 4) << bytes;
    EXPECT_EQ(mesh->num_triangles(), 4) << bytes;
  }
}

TEST_F(MeshFileTest, FaceIndexOutOfRange) {
  absl::StatusOr<Mesh> off = ReadMesh(Write(
      "i.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 9\n"));
  ASSERT_FALSE(off.ok());
  EXPECT_THAT(
      off.status().message(),
      AllOf(HasSubstr("line 10"), HasSubstr("face 3 refers to vertex 9"), HasSubstr("4 vertices")));
  absl::StatusOr<Mesh> obj = ReadMesh(
      Write("i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 5\n"));
  ASSERT_FALSE(obj.ok());
  EXPECT_THAT(obj.status().message(), HasSubstr("face 3 refers to vertex 5"));
}

TEST_F(MeshFileTest, NanCoordinate) {
  for (const char* value : {"nan", "NaN", "inf", "-inf"}) {
    absl::StatusOr<Mesh> mesh =
        ReadMesh(Write("n.off", std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n") + value +
                                    " 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
    ASSERT_FALSE(mesh.ok()) << value;
    EXPECT_THAT(mesh.status().message(),
                AllOf(HasSubstr("vertex 2"), HasSubstr("not a finite number")))
        << value;
  }
}

TEST_F(MeshFileTest, NotAMesh) {
  std::mt19937 rng(7);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(rng() & 0xff);
  for (const char* name : {"g.off", "g.obj", "g.stl", "g.ply"}) {
    absl::StatusOr<Mesh> mesh = ReadMesh(Write(name, garbage));
    EXPECT_FALSE(mesh.ok()) << name;
    EXPECT_THAT(mesh.status().message(), HasSubstr(name));
  }
  absl::StatusOr<Mesh> text = ReadMesh(Write("readme.obj", "This is a README, not a mesh.\n"));
  ASSERT_FALSE(text.ok());
  EXPECT_THAT(text.status().message(), HasSubstr("'This' is not an OBJ statement"));
  absl::StatusOr<Mesh> off = ReadMesh(Write("readme.off", "This is a README, not a mesh.\n"));
  ASSERT_FALSE(off.ok());
  EXPECT_THAT(off.status().message(), HasSubstr("expected the OFF header"));
}

TEST_F(MeshFileTest, MissingFile) {
  absl::StatusOr<Mesh> mesh = ReadMesh((dir_ / "nope.off").string());
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(mesh.status().message(), HasSubstr("no such file"));
}

TEST_F(MeshFileTest, UnsupportedExtensionAndDirectory) {
  absl::StatusOr<Mesh> txt = ReadMesh(Write("mesh.txt", "OFF\n"));
  ASSERT_FALSE(txt.ok());
  EXPECT_THAT(txt.status().message(), HasSubstr("unsupported mesh format 'txt'"));
  absl::StatusOr<Mesh> dir = ReadMesh(dir_.string());
  ASSERT_FALSE(dir.ok());
  EXPECT_THAT(dir.status().message(), HasSubstr("is a directory"));
}

TEST(ParseMesh, FromMemory) {
  absl::StatusOr<Mesh> mesh = ParseMesh(
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", "OFF");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->num_vertices(), 4);
  EXPECT_FALSE(ParseMesh("solid x\n", "3ds").ok());
}

}  // namespace
}  // namespace inscribe
