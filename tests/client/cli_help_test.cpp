// What the command line says when it is used wrongly: near matches for mistyped subcommands and
// options, each subcommand's own exit statuses, output paths and budgets refused before any
// work, the line naming what was written, progress lines off a terminal; and the default port.
#include "cli_help.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/wire/service_address.h"
#include "support/test_meshes.h"

namespace inscribe::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

std::string Eight() { return Quote(testing::TestMeshPath("eight.off")); }

fs::path TempDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_cli_help_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

TEST(EditDistance, CountsEditsAndNeighbourSwapsOnce) {
  EXPECT_EQ(EditDistance("generate", "generate"), 0);
  EXPECT_EQ(EditDistance("genrate", "generate"), 1);   // a deletion
  EXPECT_EQ(EditDistance("gneerate", "generate"), 1);  // a swap
  EXPECT_EQ(EditDistance("generat", "generate"), 1);
  EXPECT_EQ(EditDistance("", "abc"), 3);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
}

TEST(NearNames, FindsTheIntendedNameAndNothingForNonsense) {
  const std::vector<std::string> commands = {"info",  "generate", "evaluate", "deform", "distance",
                                             "scene", "urdf",     "view",     "convert"};
  EXPECT_THAT(NearNames("genrate", commands), ElementsAre("generate"));
  EXPECT_THAT(NearNames("evalute", commands), ElementsAre("evaluate"));
  EXPECT_THAT(NearNames("dist", commands), ElementsAre("distance"));  // a prefix
  EXPECT_THAT(NearNames("xyzzy", commands), IsEmpty());
  const std::vector<std::string> options = {"--max-spheres", "--max-voxels", "--voxel-size",
                                            "--cover",       "-o",           "--output"};
  EXPECT_THAT(NearNames("--max-sphere", options), ElementsAre("--max-spheres"));
  EXPECT_THAT(NearNames("--voxelsize", options), ElementsAre("--voxel-size"));
  EXPECT_EQ(DidYouMean({"a", "b", "c"}), " (did you mean a, b or c?)");
  EXPECT_EQ(DidYouMean({}), "");
}

TEST(TargetWithDefaultPort, AddsThePortOnlyWhereNoneIsGiven) {
  EXPECT_EQ(wire::TargetWithDefaultPort("localhost"), "localhost:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort(" host.example "), "host.example:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort("localhost:7000"), "localhost:7000");
  EXPECT_EQ(wire::TargetWithDefaultPort("localhost:"), "localhost:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort("10.0.0.1"), "10.0.0.1:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort("::1"), "[::1]:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort("[::1]"), "[::1]:50051");
  EXPECT_EQ(wire::TargetWithDefaultPort("[::1]:7000"), "[::1]:7000");
  EXPECT_EQ(wire::TargetWithDefaultPort("dns:///host:7000"), "dns:///host:7000");
  EXPECT_EQ(wire::TargetWithDefaultPort("unix:/tmp/inscribe.sock"), "unix:/tmp/inscribe.sock");
  EXPECT_EQ(wire::TargetWithDefaultPort("ipv4:127.0.0.1:9"), "ipv4:127.0.0.1:9");
  EXPECT_EQ(wire::TargetWithDefaultPort(""), "");
}

TEST(CliHelp, AMistypedSubcommandGetsTheNearestName) {
  EXPECT_EQ(RunCli("robot --help").exit_code, 0);  // an alias (of urdf) is a subcommand too
  const CliRun run = RunCli("genrate x.off");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("unknown subcommand 'genrate' (did you mean generate?)"));
  EXPECT_THAT(run.err, HasSubstr("the subcommands are info, generate"));
}

TEST(CliHelp, AMistypedOptionGetsTheNearestNameOfItsSubcommand) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  CliRun run = RunCli("generate " + Eight() + " --max-sphere 5");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("inscribe generate: unknown option --max-sphere (did you mean "
                                 "--max-spheres?)"));
  run = RunCli("urdf robot.urdf -o out.urdf --max-sphere=5");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("inscribe urdf: unknown option --max-sphere (did you mean "));
}

TEST(CliHelp, EachSubcommandListsOnlyItsOwnExitStatuses) {
  const CliRun generate = RunCli("generate --help");
  EXPECT_EQ(generate.exit_code, 0);
  EXPECT_THAT(generate.out, HasSubstr("--server"));
  EXPECT_THAT(generate.out, HasSubstr("69 the --server could not be reached"));
  const CliRun urdf = RunCli("urdf --help");
  EXPECT_EQ(urdf.exit_code, 0);
  EXPECT_THAT(urdf.out, Not(HasSubstr("--server")));
  EXPECT_THAT(urdf.out, Not(HasSubstr("69 ")));
  EXPECT_THAT(urdf.out, HasSubstr("1 a link was skipped"));
  const CliRun convert = RunCli("convert --help");
  EXPECT_THAT(convert.out, Not(HasSubstr("1 the mesh")));
}

TEST(CliOutputs, AnUnwritablePathOrUnknownFormatIsRefusedBeforeAnyWork) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  CliRun run = RunCli("generate " + Eight() + " -o /nonexistent-folder/spheres.json");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("directory /nonexistent-folder does not exist"));
  const fs::path dir = TempDir();
  run = RunCli("generate " + Eight() + " -o " + Quote(dir.string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("it is a directory"));
  run = RunCli("generate " + Eight() + " -o " + Quote((dir / "spheres.xyz").string()));
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("--format"));
  EXPECT_THAT(run.err, Not(HasSubstr("spheres for")));  // nothing was generated
  EXPECT_FALSE(fs::exists(dir / "spheres.xyz"));
  fs::remove_all(dir);
}

TEST(CliOutputs, AWrittenFileIsNamedWithWhatItHolds) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const std::string out = (dir / "eight.csv").string();
  const CliRun run = RunCli("generate " + Eight() + " --max-spheres 20 -o " + Quote(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, HasSubstr("inscribe: wrote " + out + " ("));
  EXPECT_THAT(run.err, HasSubstr(" spheres, csv)"));
  EXPECT_THAT(run.err, HasSubstr("internal spheres for "));
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(CliBudgets, ABudgetNoGridCanHoldIsRefusedAtOnceNamingTheLimit) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const CliRun run = RunCli("generate " + Eight() + " --max-spheres 100000000 --json");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("max_voxels"));
  EXPECT_THAT(run.err, HasSubstr("lower max_spheres or raise max_voxels"));
}

TEST(CliTiming, TheSummaryGivesThisCallsTimeAndTheGenerationsApart) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const CliRun run = RunCli("generate " + Eight() + " --max-spheres 20 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(run.out);
  ASSERT_TRUE(summary.contains("seconds"));
  ASSERT_TRUE(summary.contains("generation_seconds"));
  EXPECT_GE(summary["seconds"].get<double>(), 0.0);
  EXPECT_GE(summary["generation_seconds"].get<double>(), 0.0);
}

TEST(CliProgress, PlainLinesOffATerminalOnlyWhenAskedFor) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const fs::path dir = TempDir();
  const std::string args =
      "generate " + Eight() + " --max-spheres 20 -o " + Quote((dir / "e.json").string());
  ::unsetenv("INSCRIBE_PROGRESS");
  CliRun run = RunCli(args);  // stderr is a file here
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, Not(HasSubstr("inscribe: reading")));
  run = RunCli(args + " --progress");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, HasSubstr("inscribe: reading "));
  EXPECT_THAT(run.err, HasSubstr("inscribe: validating "));
  EXPECT_THAT(run.err, HasSubstr("inscribe: generating\n"));
  EXPECT_THAT(run.err, HasSubstr(": done in "));
  ::setenv("INSCRIBE_PROGRESS", "1", 1);
  run = RunCli(args);
  ::unsetenv("INSCRIBE_PROGRESS");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, HasSubstr("inscribe: reading "));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace inscribe::cli
