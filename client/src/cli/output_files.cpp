#include "output_files.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <iostream>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "command_outcome.h"
#include "inscribe/balls/sphere_io.h"

namespace inscribe::cli {

namespace {

std::atomic<bool> output_refused{false};

// Why `path` cannot be written, or "".
std::string WhyNotWritable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (path.empty()) return "an empty path";
  if (fs::is_directory(path, error))
    return absl::StrCat("cannot write ", path, ": it is a directory");
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  if (fs::exists(folder, error) && !fs::is_directory(folder, error)) {
    return absl::StrCat("cannot write ", path, ": ", folder.string(), " is not a directory");
  }
  if (!fs::is_directory(folder, error)) {
    return absl::StrCat("cannot write ", path, ": directory ", folder.string(), " does not exist");
  }
  if (access(folder.c_str(), W_OK) != 0) {
    return absl::StrCat("cannot write ", path, ": directory ", folder.string(), " is not writable");
  }
  if (fs::exists(path, error) && access(path.c_str(), W_OK) != 0) {
    return absl::StrCat("cannot write ", path, ": the file exists and is not writable");
  }
  return "";
}

}  // namespace

CLI::Validator WritableFile() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        std::string why = WhyNotWritable(path);
        if (!why.empty()) output_refused = true;
        return why;
      },
      "FILE (written)");
}

bool OutputPathRefused() { return output_refused; }

absl::Status CheckSphereOutputFormat(const std::string& path, const std::string& format) {
  if (path.empty() || !format.empty()) return absl::OkStatus();
  if (absl::StatusOr<SphereFileFormat> chosen = SphereFileFormatFromPath(path); !chosen.ok()) {
    return UsageError(
        absl::StrCat("cannot tell the sphere file format of ", path,
                     ": give it an extension .json, .sph, .csv, .obj or .yaml, or say --format"));
  }
  return absl::OkStatus();
}

void ReportWritten(const std::string& path, absl::string_view what) {
  std::cerr << "inscribe: wrote " << path << " (" << what << ")\n";
}

}  // namespace inscribe::cli
