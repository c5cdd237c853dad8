// `inscribe health`: the probe container health checks run, against a real inscribed process.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "absl/strings/str_cat.h"
#include "cli_run.h"
#include "support/inscribed_process.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;

class CliHealthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(server_.started());
    address_ = server_.WaitUntilListening();
    ASSERT_FALSE(address_.empty()) << server_.log();
    server_.DrainLogInBackground();
  }

  testing::InscribedProcess server_{INSCRIBED, {"--listen", "127.0.0.1:0", "--jobs", "1"}};
  std::string address_;
};

TEST_F(CliHealthTest, ServingServerExitsZero) {
  const CliRun run = RunCli("health --server " + address_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, address_ + " SERVING\n");
}

TEST_F(CliHealthTest, UnreachableReplicaExits69AndNamesIt) {
  const std::string dead = absl::StrCat("127.0.0.1:", testing::UnusedLoopbackPort());
  const CliRun run = RunCli("health --timeout 2 --server " + address_ + "," + dead);
  EXPECT_EQ(run.exit_code, 69);
  EXPECT_THAT(run.out, HasSubstr(address_ + " SERVING\n"));
  EXPECT_THAT(run.out, HasSubstr(dead + " UNREACHABLE (UNAVAILABLE"));
}

TEST_F(CliHealthTest, UnknownServiceIsNotHealthy) {
  const CliRun run = RunCli("health --server " + address_ + " --service no.such.Service");
  EXPECT_EQ(run.exit_code, 69);
  EXPECT_THAT(run.out, HasSubstr(address_ + " ERROR (NOT_FOUND"));
  // The whole server ("") is serving.
  EXPECT_EQ(RunCli("health --server " + address_ + " --service ''").exit_code, 0);
}

TEST(CliHealthUsageTest, ServerIsRequired) { EXPECT_EQ(RunCli("health").exit_code, 64); }

}  // namespace
}  // namespace inscribe
