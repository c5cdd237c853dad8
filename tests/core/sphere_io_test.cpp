// Sphere-set files: bit-exact round trips, hand-written golden files in every format, the
// .sph root sphere and the OBJ icospheres against independent computations, and the file
// system side (extensions, sniffing, atomic replacement). Bad input: sphere_io_errors_test.cpp.
#include "inscribe/balls/sphere_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "inscribe/mesh/mesh_io.h"
#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace fs = std::filesystem;

const std::string kHash = "sha256:" + std::string(64, 'a');

std::uint64_t Bits(double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

SphereFile Small() {
  SphereFile file;
  file.set.spheres = {{Vector3(0, 0, 0), 1.0}, {Vector3(1.5, -2, 0.25), 0.125}};
  file.set.contacts = {{3, Vector3(0.25, 0.25, 0.5)}, {0, Vector3(1, 0, 0)}};
  file.mesh_sha256 = kHash;
  file.params = {{"voxel_size", 0.1},
                 {"max_spheres", std::int64_t{1000}},
                 {"exact", true},
                 {"method", std::string("voxel")}};
  file.stats = {{"seconds", 0.42}, {"nerr", 0.031}};
  file.protrusions = {0.5, -0.25};
  return file;
}

// Doubles from random bit patterns (every exponent, subnormals included) plus the awkward
// fixed ones; radii are their absolute values, zero skipped.
SphereFile RandomBits(std::size_t n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<double> awkward = {-0.0,
                                       0.1,
                                       1.0 / 3,
                                       5e-324,
                                       2.2250738585072014e-308,
                                       1.7976931348623157e308,
                                       -1.7976931348623157e308,
                                       1e22,
                                       9007199254740993.0,
                                       123456789012.0};
  std::size_t next_awkward = 0;
  const auto draw = [&]() {
    if (rng() % 4 == 0) return awkward[next_awkward++ % awkward.size()];
    while (true) {
      double v;
      const std::uint64_t u = rng();
      std::memcpy(&v, &u, sizeof v);
      if (std::isfinite(v)) return v;
    }
  };
  SphereFile file;
  for (std::size_t i = 0; i < n; ++i) {
    Sphere s;
    s.center = Vector3(draw(), draw(), draw());
    do s.radius = std::abs(draw());
    while (!(s.radius > 0));
    file.set.spheres.push_back(s);
    file.set.contacts.push_back(
        {static_cast<std::int32_t>(rng() % 2147483648u), Vector3(draw(), draw(), draw())});
    file.protrusions.push_back(draw());
  }
  file.mesh_sha256 = kHash;
  file.params = {{"a", draw()}, {"b", static_cast<std::int64_t>(rng())}, {"c", false}};
  file.stats = {{"seconds", draw()}, {"note", std::string("caf\xC3\xA9 \"quoted\"\n")}};
  return file;
}

void ExpectSameSpheresBitExact(const SphereSet& a, const SphereSet& b) {
  ASSERT_EQ(a.spheres.size(), b.spheres.size());
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(Bits(a.spheres[i].center[k]), Bits(b.spheres[i].center[k])) << i << " " << k;
    }
    ASSERT_EQ(Bits(a.spheres[i].radius), Bits(b.spheres[i].radius)) << i;
  }
}

// Same names, same alternatives, doubles with the same bits (so -0.0 differs from 0.0).
void ExpectSameValuesBitExact(const NamedValues& a, const NamedValues& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].first, b[i].first);
    ASSERT_EQ(a[i].second.index(), b[i].second.index()) << a[i].first;
    if (const double* d = std::get_if<double>(&a[i].second)) {
      EXPECT_EQ(Bits(*d), Bits(std::get<double>(b[i].second))) << a[i].first;
    } else {
      EXPECT_EQ(a[i].second, b[i].second) << a[i].first;
    }
  }
}

void ExpectSameFileBitExact(const SphereFile& a, const SphereFile& b) {
  ExpectSameSpheresBitExact(a.set, b.set);
  ASSERT_EQ(a.set.contacts.size(), b.set.contacts.size());
  for (std::size_t i = 0; i < a.set.contacts.size(); ++i) {
    EXPECT_EQ(a.set.contacts[i].triangle, b.set.contacts[i].triangle);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(Bits(a.set.contacts[i].barycentric[k]), Bits(b.set.contacts[i].barycentric[k]));
    }
  }
  ASSERT_EQ(a.protrusions.size(), b.protrusions.size());
  for (std::size_t i = 0; i < a.protrusions.size(); ++i) {
    EXPECT_EQ(Bits(a.protrusions[i]), Bits(b.protrusions[i])) << i;
  }
  EXPECT_EQ(a.mesh_sha256, b.mesh_sha256);
  ExpectSameValuesBitExact(a.params, b.params);
  ExpectSameValuesBitExact(a.stats, b.stats);
}

TEST(SphereFileFormat, NamesAndExtensions) {
  EXPECT_EQ(*ParseSphereFileFormat("JSON"), SphereFileFormat::kJson);
  EXPECT_EQ(*ParseSphereFileFormat("yml"), SphereFileFormat::kYaml);
  EXPECT_THAT(ParseSphereFileFormat("ply").status().message(), HasSubstr("'ply'"));
  for (SphereFileFormat f :
       {SphereFileFormat::kJson, SphereFileFormat::kSph, SphereFileFormat::kCsv,
        SphereFileFormat::kObj, SphereFileFormat::kYaml}) {
    EXPECT_EQ(*ParseSphereFileFormat(SphereFileFormatName(f)), f);
    EXPECT_EQ(*SphereFileFormatFromPath("/a/b." + std::string(SphereFileFormatName(f))), f);
  }
  EXPECT_EQ(*SphereFileFormatFromPath("x/TREE.SPH"), SphereFileFormat::kSph);
  EXPECT_FALSE(SphereFileFormatFromPath("spheres").ok());
  EXPECT_THAT(SphereFileFormatFromPath("a.txt").status().message(), HasSubstr("a.txt"));
  EXPECT_TRUE(IsReadableSphereFileFormat(SphereFileFormat::kCsv));
  EXPECT_FALSE(IsReadableSphereFileFormat(SphereFileFormat::kObj));
}

TEST(SphereFileRoundTrip, JsonIsBitExactForEveryField) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const SphereFile original = RandomBits(2000, seed);
    absl::StatusOr<std::string> bytes = FormatSphereFile(original, SphereFileFormat::kJson);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    absl::StatusOr<SphereFile> back = ParseSphereFile(*bytes, SphereFileFormat::kJson);
    ASSERT_TRUE(back.ok()) << back.status();
    ExpectSameFileBitExact(original, *back);
  }
  // Integral doubles stay doubles and integers stay integers.
  SphereFile types;
  types.params = {{"two", 2.0}, {"also_two", std::int64_t{2}}, {"big", -(std::int64_t{1} << 62)}};
  absl::StatusOr<SphereFile> back =
      ParseSphereFile(*FormatSphereFile(types, SphereFileFormat::kJson), SphereFileFormat::kJson);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->params, types.params);
  EXPECT_TRUE(std::holds_alternative<double>(back->params[0].second));
}

TEST(SphereFileRoundTrip, CsvSphAndYamlAreBitExactForSpheres) {
  const SphereFile original = RandomBits(2000, 7);
  for (SphereFileFormat format :
       {SphereFileFormat::kCsv, SphereFileFormat::kSph, SphereFileFormat::kYaml}) {
    SCOPED_TRACE(SphereFileFormatName(format));
    for (bool header : {true, false}) {
      SphereFileWriteOptions options;
      options.csv_header = header;
      absl::StatusOr<std::string> bytes = FormatSphereFile(original, format, options);
      ASSERT_TRUE(bytes.ok()) << bytes.status();
      absl::StatusOr<SphereFile> back = ParseSphereFile(*bytes, format);
      ASSERT_TRUE(back.ok()) << back.status();
      ExpectSameSpheresBitExact(original.set, back->set);
      EXPECT_FALSE(back->set.has_contacts());
      EXPECT_TRUE(back->params.empty() && back->mesh_sha256.empty());
    }
  }
}

TEST(SphereFileRoundTrip, EmptySetInEveryReadableFormat) {
  for (SphereFileFormat format : {SphereFileFormat::kJson, SphereFileFormat::kCsv,
                                  SphereFileFormat::kSph, SphereFileFormat::kYaml}) {
    absl::StatusOr<std::string> bytes = FormatSphereFile(SphereFile{}, format);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    absl::StatusOr<SphereFile> back = ParseSphereFile(*bytes, format);
    ASSERT_TRUE(back.ok()) << SphereFileFormatName(format) << ": " << back.status();
    EXPECT_EQ(back->set.size(), 0u);
  }
}

TEST(SphereFileGolden, WritesJson) {
  EXPECT_EQ(*FormatSphereFile(Small(), SphereFileFormat::kJson),
            "{\n"
            "  \"format\": \"inscribe.spheres\",\n"
            "  \"version\": 1,\n"
            "  \"mesh_sha256\": \"" +
                kHash +
                "\",\n"
                "  \"params\": "
                "{\"voxel_size\":0.1,\"max_spheres\":1000,\"exact\":true,\"method\":\"voxel\"},\n"
                "  \"spheres\": [\n"
                "    [0.0,0.0,0.0,1.0],\n"
                "    [1.5,-2.0,0.25,0.125]\n"
                "  ],\n"
                "  \"contacts\": [\n"
                "    [3,0.25,0.25,0.5],\n"
                "    [0,1.0,0.0,0.0]\n"
                "  ],\n"
                "  \"protrusions\": [0.5,-0.25],\n"
                "  \"stats\": {\"seconds\":0.42,\"nerr\":0.031}\n"
                "}\n");
}

TEST(SphereFileGolden, WritesCsvSphYaml) {
  EXPECT_EQ(*FormatSphereFile(Small(), SphereFileFormat::kCsv),
            "x,y,z,r\n0,0,0,1\n1.5,-2,0.25,0.125\n");
  // A two-level tree, as spheretree's own flat-set writer makes: root, then the spheres.
  const std::string sph = *FormatSphereFile(Small(), SphereFileFormat::kSph);
  EXPECT_THAT(sph, StartsWith("2 2\n"));
  EXPECT_THAT(sph, ::testing::EndsWith("\n0 0 0 1 1\n1.5 -2 0.25 0.125 1\n"));
  EXPECT_EQ(*FormatSphereFile(Small(), SphereFileFormat::kYaml),
            "# inscribe spheres: 2 spheres, mesh " + kHash +
                "\n"
                "collision_spheres:\n"
                "  \"mesh\":\n"
                "    - \"center\": [0.0, 0.0, 0.0]\n"
                "      \"radius\": 1.0\n"
                "    - \"center\": [1.5, -2.0, 0.25]\n"
                "      \"radius\": 0.125\n");
  // PyYAML reads "1e+22" as a string; the mantissa always gets a '.'.
  SphereFile odd;
  odd.set.spheres = {{Vector3(1e22, -5e-324, 1.5e-7), 2e-300}};
  SphereFileWriteOptions options;
  options.yaml_link_name = "panda_link0";
  EXPECT_EQ(*FormatSphereFile(odd, SphereFileFormat::kYaml, options),
            "# inscribe spheres: 1 spheres\ncollision_spheres:\n  \"panda_link0\":\n"
            "    - \"center\": [1.0e+22, -5.0e-324, 1.5e-07]\n      \"radius\": 2.0e-300\n");
  EXPECT_THAT(*FormatSphereFile(SphereFile{}, SphereFileFormat::kYaml),
              ::testing::EndsWith("  \"mesh\": []\n"));
}

TEST(SphereFileGolden, ReadsHandWrittenJson) {
  // Integers as coordinates, unknown keys (ignored), keys in another order, a BOM-free file
  // without contacts, params or stats.
  const std::string bytes = R"({"spheres": [[1, 2, 3, 0.5], [-1e-3, 0, 2.5E2, 7]],
      "version": 1, "comment": ["ignored", {"x": 1}], "format": "inscribe.spheres"})";
  absl::StatusOr<SphereFile> file = ParseSphereFile(bytes, SphereFileFormat::kJson);
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->set.size(), 2u);
  EXPECT_EQ(file->set.spheres[0].center, Vector3(1, 2, 3));
  EXPECT_EQ(file->set.spheres[1].center, Vector3(-0.001, 0, 250));
  EXPECT_EQ(file->set.spheres[1].radius, 7);
  EXPECT_FALSE(file->set.has_contacts());
  EXPECT_TRUE(file->mesh_sha256.empty() && file->params.empty() && file->stats.empty());
  // An empty contacts array means none.
  file = ParseSphereFile(
      R"({"format":"inscribe.spheres","version":1,"spheres":[[0,0,0,1]],"contacts":[]})",
      SphereFileFormat::kJson);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_FALSE(file->set.has_contacts());
}

// A three-level binary tree as spheretree writes it: occupancy columns, one slot with an
// auxiliary sphere (ten columns), an unused slot (r = -1), a blank line between levels.
constexpr const char* kTree =
    "3 2\n"
    "0 0 0 2.5 1\n"
    "-1 0 0 1.25 1\n"
    "1 0 0 1.25 1\n"
    "\n"
    "-1.5 0 0 0.5 1\n"
    "-0.5 0 0 0.5 0.8 -0.5 0 0 0.6 0.01\n"
    "0.000000 0.000000 0.000000 -1.000000 1.000000\n"
    "1 0 0 1 1\n";

TEST(SphereFileGolden, ReadsSphereTreeLevels) {
  absl::StatusOr<SphereFile> leaves = ParseSphereFile(kTree, SphereFileFormat::kSph);
  ASSERT_TRUE(leaves.ok()) << leaves.status();
  ASSERT_EQ(leaves->set.size(), 3u);  // the unused slot is dropped
  EXPECT_EQ(leaves->set.spheres[0].center, Vector3(-1.5, 0, 0));
  EXPECT_EQ(leaves->set.spheres[1].radius, 0.5);
  EXPECT_EQ(leaves->set.spheres[2].center, Vector3(1, 0, 0));
  for (int level : {0, 1, 2}) {
    SphereFileReadOptions options;
    options.sph_level = level;
    absl::StatusOr<SphereFile> file = ParseSphereFile(kTree, SphereFileFormat::kSph, options);
    ASSERT_TRUE(file.ok()) << file.status();
    EXPECT_EQ(file->set.size(), std::vector<std::size_t>({1, 2, 3})[level]);
  }
  // Degree 0: only the root level has slots.
  absl::StatusOr<SphereFile> root = ParseSphereFile("5 0\n1 2 3 4 1\n", SphereFileFormat::kSph);
  ASSERT_TRUE(root.ok()) << root.status();
  EXPECT_EQ(root->set.size(), 0u);  // the deepest level (4) is empty
}

TEST(SphereFileGolden, ReadsCsvWithHeaderCommentsBlankLinesAndCrlf) {
  const std::string bytes =
      "\xEF\xBB\xBF# spheres of the cow\r\n"
      " X , Y , Z , Radius \r\n"
      "\r\n"
      "1,2,3,0.5   # first\r\n"
      "\t-4.5e1 ,+6, 7 ,8\n"
      "\n"
      "   # done\n"
      "0,0,0,1e-300";  // no final newline
  absl::StatusOr<SphereFile> file = ParseSphereFile(bytes, SphereFileFormat::kCsv);
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->set.size(), 3u);
  EXPECT_EQ(file->set.spheres[0].center, Vector3(1, 2, 3));
  EXPECT_EQ(file->set.spheres[1].center, Vector3(-45, 6, 7));
  EXPECT_EQ(file->set.spheres[1].radius, 8);
  EXPECT_EQ(file->set.spheres[2].radius, 1e-300);
}

// The root sphere written to .sph must contain every sphere: checked against the definition.
TEST(SphereFileSph, RootContainsEverySphere) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-100, 100), radius(1e-3, 10);
  for (int trial = 0; trial < 20; ++trial) {
    SphereFile file;
    for (int i = 0, n = 1 + static_cast<int>(rng() % 50); i < n; ++i) {
      file.set.spheres.push_back(
          {Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)});
    }
    const std::string bytes = *FormatSphereFile(file, SphereFileFormat::kSph);
    SphereFileReadOptions root_level;
    root_level.sph_level = 0;
    absl::StatusOr<SphereFile> root = ParseSphereFile(bytes, SphereFileFormat::kSph, root_level);
    ASSERT_TRUE(root.ok()) << root.status();
    ASSERT_EQ(root->set.size(), 1u);
    const Sphere& r = root->set.spheres[0];
    for (const Sphere& s : file.set.spheres) {
      EXPECT_LE((s.center - r.center).norm() + s.radius, r.radius);
    }
  }
}

// OBJ spheres, read back through CGAL's OBJ reader: the counts, every vertex on its sphere,
// and the volume against the test suite's own icosphere (an independent construction).
TEST(SphereFileObj, IcospheresAreOnTheSpheresAndOutward) {
  SphereFile file;
  file.set.spheres = {{Vector3(0, 0, 0), 1.0}, {Vector3(10, -3, 2), 0.25}, {Vector3(-5, 5, 5), 2}};
  const fs::path path = fs::temp_directory_path() / ("inscribe_obj_" + std::to_string(getpid()));
  fs::create_directories(path);
  for (int level : {0, 1, 3}) {
    SphereFileWriteOptions options;
    options.obj_subdivision = level;
    const std::string name = (path / ("s" + std::to_string(level) + ".obj")).string();
    ASSERT_TRUE(WriteSphereFile(name, file, options).ok());
    absl::StatusOr<Mesh> mesh = ReadMesh(name);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    const int per_sphere_v = 10 * (1 << (2 * level)) + 2;
    const int per_sphere_t = 20 * (1 << (2 * level));
    ASSERT_EQ(mesh->num_vertices(), 3 * per_sphere_v);
    ASSERT_EQ(mesh->num_triangles(), 3 * per_sphere_t);
    double expected_volume = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const Sphere& s = file.set.spheres[i];
      for (int v = 0; v < per_sphere_v; ++v) {
        const Vector3 p =
            mesh->vertices.row(static_cast<Eigen::Index>(i) * per_sphere_v + v).transpose();
        EXPECT_NEAR((p - s.center).norm(), s.radius, 1e-12 * (1 + s.center.norm()));
      }
      expected_volume += SignedVolume(testing::Icosphere(level, s.center, s.radius));
    }
    EXPECT_NEAR(SignedVolume(*mesh), expected_volume, 1e-9 * expected_volume);
  }
  fs::remove_all(path);
}

class SphereFileOnDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("inscribe_sphio_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string Slurp(const std::string& name) const {
    std::ifstream in(Path(name), std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
  }
  fs::path dir_;
};

TEST_F(SphereFileOnDisk, WritesByExtensionAndReadsBack) {
  const SphereFile original = Small();
  for (const char* name : {"a.json", "a.sph", "a.csv", "A.CSV"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(WriteSphereFile(Path(name), original).ok());
    absl::StatusOr<SphereFile> back = ReadSphereFile(Path(name));
    ASSERT_TRUE(back.ok()) << back.status();
    ExpectSameSpheresBitExact(original.set, back->set);
  }
  ExpectSameFileBitExact(original, *ReadSphereFile(Path("a.json")));
  // The format option overrides the extension.
  SphereFileWriteOptions as_csv;
  as_csv.format = SphereFileFormat::kCsv;
  ASSERT_TRUE(WriteSphereFile(Path("b.txt"), original, as_csv).ok());
  EXPECT_THAT(Slurp("b.txt"), StartsWith("x,y,z,r\n"));
  SphereFileReadOptions read_csv;
  read_csv.format = SphereFileFormat::kCsv;
  EXPECT_EQ(ReadSphereFile(Path("b.txt"), read_csv)->set.size(), 2u);
}

TEST_F(SphereFileOnDisk, SniffsUnknownExtensions) {
  const SphereFile original = Small();
  for (SphereFileFormat format : {SphereFileFormat::kJson, SphereFileFormat::kSph,
                                  SphereFileFormat::kCsv, SphereFileFormat::kYaml}) {
    SCOPED_TRACE(SphereFileFormatName(format));
    SphereFileWriteOptions options;
    options.format = format;
    for (bool header : {true, false}) {
      options.csv_header = header;
      ASSERT_TRUE(WriteSphereFile(Path("spheres"), original, options).ok());
      absl::StatusOr<SphereFile> back = ReadSphereFile(Path("spheres"));
      ASSERT_TRUE(back.ok()) << back.status();
      ExpectSameSpheresBitExact(original.set, back->set);
    }
  }
  std::ofstream(Path("notes.txt")) << "just some words\n";
  EXPECT_THAT(ReadSphereFile(Path("notes.txt")).status().message(),
              AllOf(HasSubstr("notes.txt"), HasSubstr("cannot tell")));
}

TEST_F(SphereFileOnDisk, ReplacesAtomicallyAndLeavesNoTemporaryFiles) {
  std::ofstream(Path("s.csv")) << "old";
  SphereFile file = Small();
  ASSERT_TRUE(WriteSphereFile(Path("s.csv"), file).ok());
  EXPECT_EQ(Slurp("s.csv"), *FormatSphereFile(file, SphereFileFormat::kCsv));
  // A failing format leaves the old file untouched.
  file.set.spheres[1].radius = -1;
  const absl::Status bad = WriteSphereFile(Path("s.csv"), file);
  EXPECT_THAT(bad.message(), AllOf(HasSubstr("s.csv"), HasSubstr("sphere 1: radius -1")));
  EXPECT_EQ(Slurp("s.csv"), *FormatSphereFile(Small(), SphereFileFormat::kCsv));
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) entries += entry.is_regular_file();
  EXPECT_EQ(entries, 1u);
  // Directory missing: NOT_FOUND, nothing created.
  const absl::Status missing = WriteSphereFile(Path("no/such/dir/s.json"), Small());
  EXPECT_EQ(missing.code(), absl::StatusCode::kNotFound) << missing;
  EXPECT_THAT(missing.message(), HasSubstr("no/such/dir/s.json"));
}

}  // namespace
}  // namespace inscribe
