// libFuzzer target: the robot sphere readers (robot_spheres.h). The first byte picks the format
// (value % 5: curobo, xrdf, srdf, urdf, morphit); the rest goes through ParseRobotSpheres. A file
// that parses must give a model CheckRobotSpheres accepts, and one its writer takes (the URDF
// layouts written into the input itself) must read back as the same model. A writer may refuse
// what its format cannot carry (a link name YAML keys cannot hold, a MorphIt sphere link name
// the URDF already uses). Any break aborts with the reason.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "inscribe/robot/robot_spheres.h"

namespace {

using inscribe::robot::RobotSpheres;
using inscribe::robot::RobotSpheresFormat;

[[noreturn]] void Fail(const char* what, RobotSpheresFormat format) {
  std::fprintf(stderr, "fuzz_robot_spheres (%s): %s\n",
               inscribe::robot::RobotSpheresFormatName(format), what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  constexpr RobotSpheresFormat kFormats[] = {RobotSpheresFormat::kCurobo, RobotSpheresFormat::kXrdf,
                                             RobotSpheresFormat::kSrdf, RobotSpheresFormat::kUrdf,
                                             RobotSpheresFormat::kMorphit};
  const RobotSpheresFormat format = kFormats[data[0] % 5];
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  const absl::StatusOr<RobotSpheres> model = inscribe::robot::ParseRobotSpheres(bytes, format);
  if (!model.ok()) {
    if (model.status().message().empty()) Fail("a refusal without a message", format);
    return 0;
  }
  if (!inscribe::robot::CheckRobotSpheres(*model).ok())
    Fail("the reader's model is invalid", format);
  inscribe::robot::RobotSpheresWriteOptions options;
  if (format == RobotSpheresFormat::kUrdf || format == RobotSpheresFormat::kMorphit) {
    options.base = bytes;
  }
  const absl::StatusOr<std::string> written =
      inscribe::robot::FormatRobotSpheres(*model, format, options);
  if (!written.ok()) return 0;
  const absl::StatusOr<RobotSpheres> back = inscribe::robot::ParseRobotSpheres(*written, format);
  if (!back.ok()) Fail("what the writer wrote does not read back", format);
  if (!(*back == inscribe::robot::RobotSpheresCarried(*model, format))) {
    Fail("the model read back differs", format);
  }
  return 0;
}
