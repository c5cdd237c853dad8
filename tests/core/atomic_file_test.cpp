#include "inscribe/base/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace inscribe {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("inscribe_atomic_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Everything in dir_ apart from `keep`: what a write leaves behind.
  int OtherEntries(const fs::path& keep) const {
    int n = 0;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir_)) {
      n += entry.path() != keep;
    }
    return n;
  }

  fs::path dir_;
};

TEST_F(AtomicFile, WritesAndReplacesWholeContents) {
  const fs::path path = dir_ / "page.html";
  ASSERT_TRUE(WriteFileAtomically(path.string(), "first, longer contents").ok());
  EXPECT_EQ(Read(path), "first, longer contents");
  std::string binary("a\0b", 3);
  ASSERT_TRUE(WriteFileAtomically(path.string(), binary).ok());
  EXPECT_EQ(Read(path), binary);
  ASSERT_TRUE(WriteFileAtomically(path.string(), "").ok());
  EXPECT_EQ(fs::file_size(path), 0u);
  EXPECT_EQ(OtherEntries(path), 0);  // no temporary left
}

TEST_F(AtomicFile, FailuresNameThePathAndLeaveNothing) {
  const fs::path missing_dir = dir_ / "no-such-dir" / "page.html";
  absl::Status status = WriteFileAtomically(missing_dir.string(), "x");
  EXPECT_EQ(status.code(), absl::StatusCode::kNotFound) << status;
  EXPECT_NE(status.message().find(missing_dir.string()), std::string::npos) << status;

  // Renaming over a directory fails after the temporary was written: it must be removed.
  const fs::path directory = dir_ / "a-directory";
  fs::create_directories(directory);
  status = WriteFileAtomically(directory.string(), "x");
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find(directory.string()), std::string::npos) << status;
  EXPECT_TRUE(fs::is_directory(directory));
  EXPECT_EQ(OtherEntries(directory), 0);
}

}  // namespace
}  // namespace inscribe
