// Bad sphere files and bad sphere sets: every refusal names the line or index and the problem,
// and a seeded mutation smoke (flipped bytes, cuts, hostile tokens, repeated spans) checks that
// no input crashes, hangs or yields spheres a writer would refuse. Run it under ASan
// (scripts/test --sanitize) to see memory errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "inscribe/balls/sphere_io.h"

namespace inscribe {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

namespace fs = std::filesystem;

std::string Message(const absl::StatusOr<SphereFile>& file) {
  EXPECT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), absl::StatusCode::kInvalidArgument) << file.status();
  return std::string(file.status().message());
}

std::string JsonError(const std::string& bytes) {
  return Message(ParseSphereFile(bytes, SphereFileFormat::kJson));
}
std::string CsvError(const std::string& bytes) {
  return Message(ParseSphereFile(bytes, SphereFileFormat::kCsv));
}
std::string SphError(const std::string& bytes, int level = -1) {
  SphereFileReadOptions options;
  options.sph_level = level;
  return Message(ParseSphereFile(bytes, SphereFileFormat::kSph, options));
}

// A valid JSON document around a "spheres" value and extra members.
std::string Doc(const std::string& spheres, const std::string& extra = "") {
  return R"({"format":"inscribe.spheres","version":1,"spheres":)" + spheres + extra + "}";
}

// Thirteen unit spheres along x; `bad` replaces the radius of sphere 12.
std::string ThirteenSpheresCsv(const std::string& bad) {
  std::string csv = "x,y,z,r\n";
  for (int i = 0; i < 13; ++i) {
    csv += std::to_string(i) + ",0,0," + (i == 12 ? bad : "1") + "\n";
  }
  return csv;
}

TEST(SphereFileErrors, Json) {
  EXPECT_THAT(JsonError(std::string("\0\xff{garbage", 10)),
              AllOf(HasSubstr("json data: not valid JSON"), HasSubstr("line 1")));
  EXPECT_THAT(JsonError("[1, 2]"), HasSubstr("top level is array"));
  EXPECT_THAT(JsonError(R"({"version":1,"spheres":[]})"), HasSubstr("missing \"format\""));
  EXPECT_THAT(
      JsonError(R"({"format":"other","version":1,"spheres":[]})"),
      AllOf(HasSubstr("\"format\" is '\"other\"'"), HasSubstr("expected \"inscribe.spheres\"")));
  EXPECT_THAT(JsonError(R"({"format":"inscribe.spheres","spheres":[]})"),
              HasSubstr("missing \"version\""));
  EXPECT_THAT(JsonError(R"({"format":"inscribe.spheres","version":2,"spheres":[]})"),
              HasSubstr("unsupported version 2 (this reader knows version 1)"));
  EXPECT_THAT(JsonError(R"({"format":"inscribe.spheres","version":"1","spheres":[]})"),
              HasSubstr("expected an integer"));
  EXPECT_THAT(JsonError(R"({"format":"inscribe.spheres","version":1})"),
              HasSubstr("missing \"spheres\""));
  EXPECT_THAT(JsonError(Doc("{}")), HasSubstr("\"spheres\" is object, expected an array"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1],[1,2,3]]")),
              HasSubstr("sphere 1: expected an array of 4 numbers [x, y, z, r], found 3"));
  EXPECT_THAT(JsonError(Doc("[[0,0,\"z\",1]]")),
              HasSubstr("sphere 0: element 2 is string '\"z\"', expected a number"));
  std::string spheres = "[";
  for (int i = 0; i < 12; ++i) spheres += "[0,0,0,1],";
  EXPECT_THAT(JsonError(Doc(spheres + "[0,0,0,-1]]")),
              HasSubstr("sphere 12: radius -1 is not positive"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,0]]")), HasSubstr("sphere 0: radius 0 is not positive"));
  EXPECT_THAT(JsonError(Doc("[[0,0,1e999,1]]")), HasSubstr("number overflow"));
  EXPECT_THAT(JsonError(Doc("[[0,NaN,0,1]]")), HasSubstr("not valid JSON"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1],[0,0,0,1]]", R"(,"contacts":[[0,1,0,0]])")),
              HasSubstr("1 contacts for 2 spheres (need one per sphere, or none)"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1],[0,0,0,1]]", R"(,"protrusions":[0.5])")),
              HasSubstr("1 protrusions for 2 spheres (need one per sphere, or none)"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"protrusions":["x"])")),
              AllOf(HasSubstr("protrusion 0: "), HasSubstr(" is not a number")));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"protrusions":[1e999])")),
              HasSubstr("number overflow"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"protrusions":{})")),
              HasSubstr("\"protrusions\" is object, expected an array"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"contacts":[[-1,1,0,0]])")),
              HasSubstr("contact 0: triangle -1 is negative"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"contacts":[[1.5,1,0,0]])")),
              HasSubstr("contact 0: triangle '1.5' is not an integer"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"contacts":[[2147483648,1,0,0]])")),
              HasSubstr("beyond the largest triangle index"));
  EXPECT_THAT(JsonError(Doc("[[0,0,0,1]]", R"(,"contacts":[[0,1,0]])")),
              HasSubstr("contact 0: expected an array of 4 numbers [triangle, b0, b1, b2]"));
  EXPECT_THAT(JsonError(Doc("[]", R"(,"params":{"x":[1,2]})")),
              HasSubstr("params 'x': array values are not supported"));
  EXPECT_THAT(JsonError(Doc("[]", R"(,"stats":{"n":18446744073709551615})")),
              HasSubstr("stats 'n': 18446744073709551615 does not fit"));
  EXPECT_THAT(JsonError(Doc("[]", R"(,"params":3)")), HasSubstr("\"params\" is number"));
  EXPECT_THAT(JsonError(Doc("[]", R"(,"mesh_sha256":"md5:abc")")),
              HasSubstr("mesh_sha256 'md5:abc' is not \"sha256:\" followed by 64"));
  // Deep nesting: refused without exhausting the stack.
  EXPECT_THAT(JsonError(Doc(std::string(100000, '['))), HasSubstr("not valid JSON"));
}

TEST(SphereFileErrors, JsonEveryTruncationIsRefused) {
  SphereFile file;
  file.set.spheres = {{Vector3(1, 2, 3), 0.5}, {Vector3(-1, 0.25, 8), 2}};
  file.set.contacts = {{4, Vector3(0.2, 0.3, 0.5)}, {9, Vector3(1, 0, 0)}};
  file.params = {{"voxel_size", 0.1}};
  const std::string bytes = *FormatSphereFile(file, SphereFileFormat::kJson);
  for (std::size_t n = 0; n < bytes.size() - 1; ++n) {  // the last byte is a newline
    EXPECT_FALSE(ParseSphereFile(bytes.substr(0, n), SphereFileFormat::kJson).ok()) << n;
  }
}

TEST(SphereFileErrors, Csv) {
  EXPECT_EQ(CsvError("x,y,z,r\n0,0,0,1\n1,1,1,1\n1,2,3\n"),
            "csv data: line 4: expected 4 numbers x,y,z,r, found 3");
  EXPECT_THAT(CsvError("1 2 3 4\n"),
              HasSubstr("line 1: expected 4 numbers x,y,z,r, found 1 (fields are separated"));
  EXPECT_THAT(CsvError("0,0,0,1,\n"), HasSubstr("found 5"));
  EXPECT_THAT(CsvError(ThirteenSpheresCsv("-1")),
              HasSubstr("line 14: sphere 12: radius -1 is not positive"));
  EXPECT_THAT(CsvError(ThirteenSpheresCsv("0")), HasSubstr("sphere 12: radius 0 is not positive"));
  EXPECT_THAT(CsvError(ThirteenSpheresCsv("nan")),
              HasSubstr("sphere 12: radius nan is not finite"));
  EXPECT_THAT(CsvError("0,inf,0,1\n"), HasSubstr("line 1: sphere 0: center y inf is not finite"));
  EXPECT_THAT(CsvError("0,abc,0,1\n"), HasSubstr("line 1: y: 'abc' is not a number"));
  EXPECT_THAT(CsvError("0,,0,1\n"), HasSubstr("line 1: y: empty field"));
  EXPECT_THAT(CsvError("0,0,1e999,1\n"), HasSubstr("z: '1e999' is out of the range of a double"));
  EXPECT_THAT(CsvError("0,0,0x1,1\n"), HasSubstr("'0x1' is not a number"));
  EXPECT_THAT(CsvError(std::string("0,0,\x01\xfe,1\n")), HasSubstr("'\\x01\\xfe'"));
  EXPECT_THAT(CsvError("x,y,z,r\nx,y,z,r\n"), HasSubstr("line 2: x: 'x' is not a number"));
}

constexpr const char* kTree =
    "3 2\n"
    "0 0 0 2.5 1\n"
    "-1 0 0 1.25 1\n"
    "1 0 0 1.25 1\n"
    "-1.5 0 0 0.5 1\n"
    "-0.5 0 0 0.5 1\n"
    "0 0 0 -1 1\n"
    "1 0 0 1 1\n";

TEST(SphereFileErrors, Sph) {
  EXPECT_THAT(SphError(""), HasSubstr("sph data: file is empty"));
  EXPECT_THAT(SphError("\n \n"), HasSubstr("file is empty"));
  EXPECT_THAT(SphError("spheres 2\n"),
              HasSubstr("line 1: expected the header \"levels degree\" (two integers), found "
                        "'spheres 2'"));
  EXPECT_THAT(SphError("3\n"), HasSubstr("line 1: expected the header"));
  EXPECT_THAT(SphError("99999999999999999999 2\n"), HasSubstr("expected the header"));
  EXPECT_THAT(SphError("0 2\n"), HasSubstr("the tree has 0 levels; it needs at least 1"));
  EXPECT_THAT(SphError("2 -3\n"), HasSubstr("branching factor -3 is negative"));
  EXPECT_THAT(SphError(kTree, 3), HasSubstr("level 3 requested, but the tree has 3 levels"));
  std::string truncated(kTree);
  truncated.resize(truncated.rfind("1 0 0 1 1"));
  EXPECT_THAT(SphError(truncated),
              HasSubstr("file ends after line 7 in level 2 after 3 of 4 slots (header: 3 levels, "
                        "branching factor 2; truncated?)"));
  EXPECT_THAT(SphError(std::string(kTree) + "2 2 2 2 2\n"),
              HasSubstr("line 9: content after the last level of the tree"));
  EXPECT_THAT(SphError("2 1\n0 0 0 1 1\nnan 0 0 1 1\n"),
              HasSubstr("line 3: level 1 slot 0: x nan is not finite"));
  EXPECT_THAT(SphError("2 1\n0 0 0 1 1\n0 0 0 inf 1\n"), HasSubstr("r inf is not finite"));
  EXPECT_THAT(SphError("2 1\n0 0 0 1 1\n0 0 0\n"),
              HasSubstr("line 3: level 1 slot 0: expected 4 to 10 numbers (x y z r ...), found 3"));
  EXPECT_THAT(SphError("1 1\n0 0 0 1 1 1 1 1 1 1 1 1\n"), HasSubstr("found more than 10"));
  EXPECT_THAT(SphError("1 1\n0 0 zero 1\n"), HasSubstr("column 3: 'zero' is not a number"));
}

// Declared counts far beyond the file: refused at the end of the (short) file, quickly and
// without reserving anything from the count.
TEST(SphereFileErrors, SphHugeDeclaredCounts) {
  const auto start = std::chrono::steady_clock::now();
  for (const std::string header :
       {"2 9223372036854775807", "64 4000000000", "2000000000 1", "2147483647 2", "3 3037000500"}) {
    SCOPED_TRACE(header);
    EXPECT_THAT(SphError(header + "\n0 0 0 1 1\n1 1 1 1 1\n"), HasSubstr("truncated?"));
  }
  // Degree 0 with a huge level count: every level after the root is empty, so the tree ends.
  SphereFileReadOptions options;
  EXPECT_TRUE(ParseSphereFile("2000000000 0\n0 0 0 1 1\n", SphereFileFormat::kSph, options).ok());
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
}

TEST(SphereFileErrors, WritersRefuseWhatReadersWouldRefuse) {
  const auto error = [](const SphereFile& file, SphereFileFormat format,
                        const SphereFileWriteOptions& options = {}) {
    absl::StatusOr<std::string> bytes = FormatSphereFile(file, format, options);
    EXPECT_FALSE(bytes.ok());
    EXPECT_EQ(bytes.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(bytes.status().message());
  };
  SphereFile file;
  for (int i = 0; i < 13; ++i) file.set.spheres.push_back({Vector3(i, 0, 0), 1.0});
  file.set.spheres[12].radius = -1;
  for (SphereFileFormat format :
       {SphereFileFormat::kJson, SphereFileFormat::kSph, SphereFileFormat::kCsv,
        SphereFileFormat::kObj, SphereFileFormat::kYaml}) {
    EXPECT_EQ(error(file, format), "sphere 12: radius -1 is not positive");
  }
  file.set.spheres[12].radius = 1;
  file.set.spheres[3].center.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error(file, SphereFileFormat::kCsv), "sphere 3: center y nan is not finite");
  file.set.spheres[3].center.y() = 0;
  file.set.contacts.resize(12);
  EXPECT_THAT(error(file, SphereFileFormat::kJson), HasSubstr("12 contacts for 13 spheres"));
  file.set.contacts.assign(13, SurfaceContact{0, Vector3(1, 0, 0)});
  file.set.contacts[5].triangle = -1;
  EXPECT_THAT(error(file, SphereFileFormat::kJson), HasSubstr("contact 5: triangle -1"));
  file.set.contacts[5] = {0, Vector3(std::numeric_limits<double>::infinity(), 0, 0)};
  EXPECT_THAT(error(file, SphereFileFormat::kJson), HasSubstr("contact 5: barycentric"));
  file.set.contacts.clear();

  SphereFile values = file;
  values.params = {{"a", 1.0}, {"a", 2.0}};
  EXPECT_THAT(error(values, SphereFileFormat::kJson), HasSubstr("params 'a': the name appears"));
  values.params = {{"nerr", std::numeric_limits<double>::infinity()}};
  EXPECT_THAT(error(values, SphereFileFormat::kJson), HasSubstr("params 'nerr': inf is not"));
  values.params = {};
  values.stats = {{"note", std::string("\xff\xfe")}};
  EXPECT_THAT(error(values, SphereFileFormat::kJson), HasSubstr("stats 'note': not valid UTF-8"));
  values.stats = {{"\xc3", 1.0}};
  EXPECT_THAT(error(values, SphereFileFormat::kJson), HasSubstr("not valid UTF-8"));
  values.stats = {};
  values.mesh_sha256 = "sha256:ABC";
  EXPECT_THAT(error(values, SphereFileFormat::kCsv), HasSubstr("mesh_sha256 'sha256:ABC'"));

  SphereFileWriteOptions options;
  options.obj_subdivision = 6;
  EXPECT_THAT(error(file, SphereFileFormat::kObj, options), HasSubstr("outside 0..5"));
  options.yaml_link_name = "a link: x";
  EXPECT_THAT(error(file, SphereFileFormat::kYaml, options), HasSubstr("'a link: x'"));
}

TEST(SphereFileErrors, Files) {
  const fs::path dir = fs::temp_directory_path() / ("inscribe_sphf_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const absl::StatusOr<SphereFile> missing = ReadSphereFile((dir / "none.json").string());
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("none.json: no such file"));
  EXPECT_THAT(Message(ReadSphereFile(dir.string())), HasSubstr("is a directory"));
  std::ofstream(dir / "s.obj") << "v 0 0 0\n";
  EXPECT_THAT(Message(ReadSphereFile((dir / "s.obj").string())),
              HasSubstr("s.obj: obj sphere files are write-only"));
  EXPECT_THAT(Message(ParseSphereFile("", SphereFileFormat::kObj)), HasSubstr("write-only"));
  std::ofstream(dir / "bad.csv") << "0,0,0,1\n0,0,0\n";
  EXPECT_THAT(Message(ReadSphereFile((dir / "bad.csv").string())),
              HasSubstr("bad.csv: line 2: expected 4 numbers x,y,z,r, found 3"));
  EXPECT_THAT(WriteSphereFile((dir / "s.ply").string(), SphereFile{}).message(),
              HasSubstr("unknown sphere file extension 'ply'"));
  fs::remove_all(dir);
}

std::string Mutate(std::string data, std::mt19937& rng) {
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n)(rng); };
  static const char* kTokens[] = {"nan", "-1", "1e999", "0",  "99999999999999999999", "inf", "-0",
                                  "",    "[",  "{",     "\"", "9223372036854775807",  ",",   "\x00",
                                  "2",   "\n", "1e-400"};
  switch (rng() % 4) {
    case 0:  // flip bytes
      for (std::size_t i = 0, n = 1 + pick(7); i < n && !data.empty(); ++i) {
        data[pick(data.size() - 1)] = static_cast<char>(rng() & 0xff);
      }
      break;
    case 1:  // cut
      data.resize(pick(data.size()));
      break;
    case 2: {  // replace a token
      const std::size_t at = pick(data.size());
      std::size_t end = data.find_first_of(" ,[]\n", at);
      if (end == std::string::npos) end = data.size();
      data.replace(at, end - at, kTokens[rng() % (sizeof kTokens / sizeof *kTokens)]);
      break;
    }
    default: {  // repeat a span
      const std::size_t at = pick(data.size());
      const std::string span = data.substr(at, 1 + pick(60));
      for (std::size_t k = 0, n = 1 + pick(3); k < n; ++k) data.insert(at, span);
    }
  }
  return data;
}

// Whatever parses must satisfy the readers' promises and survive a write + read unchanged;
// whatever is refused gets a non-empty, printable-ASCII message. INSCRIBE_MUTATIONS sets the
// count per seed file (default 1000, four seed files); INSCRIBE_MUTATION_SEED the stream.
TEST(SphereFileMutation, NeverCrashesAndEveryOutcomeIsClean) {
  const char* env = std::getenv("INSCRIBE_MUTATIONS");
  const int kMutationsPerSeed = env != nullptr ? std::atoi(env) : 1000;
  const char* seed_env = std::getenv("INSCRIBE_MUTATION_SEED");
  std::mt19937 rng(seed_env != nullptr ? static_cast<unsigned>(std::atoi(seed_env)) : 2026u);
  SphereFile seed;
  for (int i = 0; i < 12; ++i) {
    seed.set.spheres.push_back({Vector3(0.5 * i, -1.25 * i, 3), 0.1 + i});
    seed.set.contacts.push_back({i * 7, Vector3(0.25, 0.25, 0.5)});
  }
  seed.mesh_sha256 = "sha256:" + std::string(64, '0');
  seed.params = {{"voxel_size", 0.1}, {"max", std::int64_t{100}}, {"name", std::string("x")}};
  seed.stats = {{"seconds", 0.42}, {"exact", true}};
  const std::vector<std::pair<SphereFileFormat, std::string>> seeds = {
      {SphereFileFormat::kJson, *FormatSphereFile(seed, SphereFileFormat::kJson)},
      {SphereFileFormat::kSph, *FormatSphereFile(seed, SphereFileFormat::kSph)},
      {SphereFileFormat::kSph, kTree},
      {SphereFileFormat::kCsv, "# c\r\n" + *FormatSphereFile(seed, SphereFileFormat::kCsv)}};
  const fs::path path = fs::temp_directory_path() / ("inscribe_sphm_" + std::to_string(getpid()));
  int parsed = 0, refused = 0;
  for (const auto& [format, original] : seeds) {
    for (int i = 0; i < kMutationsPerSeed; ++i) {
      const std::string bytes = Mutate(original, rng);
      absl::StatusOr<SphereFile> file = ParseSphereFile(bytes, format);
      if (i % 50 == 0) {  // also through the file system, the format sniffed from the bytes
        std::ofstream(path, std::ios::binary) << bytes;
        absl::StatusOr<SphereFile> read = ReadSphereFile(path.string());
        if (!read.ok()) {
          EXPECT_THAT(read.status().message(), HasSubstr(path.string()));
        }
      }
      if (!file.ok()) {
        ++refused;
        const absl::string_view message = file.status().message();
        EXPECT_EQ(file.status().code(), absl::StatusCode::kInvalidArgument);
        EXPECT_FALSE(message.empty());
        for (char c : message) ASSERT_TRUE(c >= 0x20 && c < 0x7f) << message;
        continue;
      }
      ++parsed;
      for (const Sphere& s : file->set.spheres) {
        ASSERT_TRUE(s.center.allFinite() && std::isfinite(s.radius) && s.radius > 0);
      }
      ASSERT_TRUE(!file->set.has_contacts() || file->set.contacts.size() == file->set.size());
      absl::StatusOr<std::string> again = FormatSphereFile(*file, format);
      ASSERT_TRUE(again.ok()) << again.status();
      absl::StatusOr<SphereFile> back = ParseSphereFile(*again, format);
      ASSERT_TRUE(back.ok()) << back.status();
      EXPECT_EQ(*FormatSphereFile(*back, format), *again);
    }
  }
  fs::remove(path);
  EXPECT_GT(parsed, kMutationsPerSeed / 5);
  EXPECT_GT(refused, kMutationsPerSeed / 5);
}

}  // namespace
}  // namespace inscribe
