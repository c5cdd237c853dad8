// Mutated mesh files (flipped bytes, cuts, repeated spans, hostile tokens) through the whole
// loading path: every outcome is either a mesh or an error naming the file, never a crash, a
// hang or an allocation the file cannot justify. A deterministic smoke; libFuzzer goes deeper.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "mesh/mesh_file_diagnosis.h"
#include "support/cgal_mesh_writer.h"
#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

namespace fs = std::filesystem;

std::string WriteSeed(const fs::path& path, const Mesh& mesh, bool binary) {
  EXPECT_TRUE(testing::WriteMeshWithCgal(path.string(), mesh, binary));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::string Mutate(std::string data, std::mt19937& rng) {
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n)(rng); };
  static const char* kTokens[] = {"nan", "-1", "99999999999", "1e308",  "inf", "-0", "4294967296",
                                  "3",   "",   "\x01",        "1e-320", "0x10"};
  switch (rng() % 4) {
    case 0:  // flip bytes
      for (std::size_t i = 0, n = 1 + pick(15); i < n && !data.empty(); ++i) {
        data[pick(data.size() - 1)] = static_cast<char>(rng() & 0xff);
      }
      break;
    case 1:  // cut
      data.resize(pick(data.size()));
      break;
    case 2: {  // replace a whitespace-separated token
      std::size_t at = pick(data.size());
      std::size_t end = data.find_first_of(" \n", at);
      if (end == std::string::npos) end = data.size();
      data.replace(at, end - at, kTokens[rng() % (sizeof kTokens / sizeof *kTokens)]);
      break;
    }
    default: {  // repeat a span
      const std::size_t at = pick(data.size());
      const std::string span = data.substr(at, 1 + pick(200));
      for (std::size_t k = 0, n = 1 + pick(3); k < n; ++k) data.insert(at, span);
    }
  }
  return data;
}

// INSCRIBE_MUTATIONS raises the count for a longer local run (the suite uses 150 per seed
// file); INSCRIBE_MUTATION_SEED changes the random stream (default 2026).
TEST(MeshIoMutation, NeverCrashesAndAlwaysNamesTheFile) {
  const char* env = std::getenv("INSCRIBE_MUTATIONS");
  const int kMutationsPerSeed = env != nullptr ? std::atoi(env) : 150;
  const fs::path dir = fs::temp_directory_path() / ("inscribe_mut_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Mesh seed = testing::Icosphere(1);
  const char* seed_env = std::getenv("INSCRIBE_MUTATION_SEED");
  std::mt19937 rng(seed_env != nullptr ? static_cast<unsigned>(std::atoi(seed_env)) : 2026u);
  int parsed = 0, refused = 0;
  for (const auto& [name, binary] :
       std::vector<std::pair<std::string, bool>>{{"seed.off", false},
                                                 {"seed.obj", false},
                                                 {"seed.stl", false},
                                                 {"seedb.stl", true},
                                                 {"seed.ply", false},
                                                 {"seedb.ply", true}}) {
    const std::string original = WriteSeed(dir / name, seed, binary);
    for (int i = 0; i < kMutationsPerSeed; ++i) {
      const fs::path path = dir / ("m_" + name);
      std::ofstream(path, std::ios::binary) << Mutate(original, rng);
      absl::StatusOr<Mesh> mesh = ReadMesh(path.string());
      if (!mesh.ok()) {
        ++refused;
        EXPECT_NE(mesh.status().message().find(path.string()), std::string::npos) << mesh.status();
        continue;
      }
      ++parsed;
      // Whatever parsed must survive validation and hashing.
      const ValidatedMesh validated = ValidateMesh(*std::move(mesh));
      EXPECT_EQ(validated.report.usable(), validated.report.first_error().empty());
      (void)MeshSha256(validated.mesh);
    }
  }
  fs::remove_all(dir);
  // Both outcomes must occur, or the mutations are not exercising anything.
  EXPECT_GT(parsed, 50);
  EXPECT_GT(refused, 50);
}

// The OFF guard's reading of a record (its fast path for plain integers) against the stream
// CGAL reads with, on records made of plain numbers, signs, decimals, exponents, long digit
// runs, glued tokens and junk.
TEST(MeshIoMutation, OffRecordNumbersAreTheStreamsNumbers) {
  const auto stream_numbers = [](const std::string& record) {
    std::vector<double> numbers;
    std::istringstream in(record);
    double value = 0;
    while (in >> value) numbers.push_back(value);
    return numbers;
  };
  const std::vector<std::string> pieces = {"3",
                                           "0",
                                           "12",
                                           "007",
                                           "123456789012345",
                                           "1234567890123456",
                                           "99999999999999999999",
                                           "-1",
                                           "+4",
                                           "3-1",
                                           "1.5",
                                           ".5",
                                           "1e3",
                                           "2E-2",
                                           "x",
                                           "0x10",
                                           "nan",
                                           "inf",
                                           "-",
                                           "4a",
                                           "1,2",
                                           "\t",
                                           " ",
                                           "  ",
                                           "\r",
                                           "\v",
                                           "\f",
                                           "18446744073709551617"};
  std::mt19937 random(7);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string record;
    const int tokens = static_cast<int>(random() % 7);
    for (int t = 0; t < tokens; ++t) {
      record += pieces[random() % pieces.size()];
      if (random() % 4 != 0) record += (random() % 2 == 0) ? " " : "\t";
    }
    const std::vector<double> expected = stream_numbers(record);
    const std::vector<double> got = internal::CgalRecordNumbers(record);
    ASSERT_EQ(got.size(), expected.size()) << "record '" << record << "'";
    for (std::size_t i = 0; i < got.size(); ++i) {
      // Bit for bit (NaN compared as NaN).
      ASSERT_TRUE(got[i] == expected[i] || (std::isnan(got[i]) && std::isnan(expected[i])))
          << "record '" << record << "' number " << i << ": " << got[i] << " vs " << expected[i];
    }
  }
  EXPECT_EQ(internal::CgalRecordNumbers("3 10 11 12"), (std::vector<double>{3, 10, 11, 12}));
  EXPECT_EQ(internal::CgalRecordNumbers("3-1"), (std::vector<double>{3, -1}));
}

}  // namespace
}  // namespace inscribe
