#include "client/headless_chromium.h"

#include <png.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unordered_set>

namespace inscribe::testing {
namespace {

namespace fs = std::filesystem;

std::string ShellQuote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

int LargestChannelDifference(const std::uint8_t* a, const std::uint8_t* b) {
  int largest = 0;
  for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(int{a[k]} - int{b[k]}));
  return largest;
}

// Runs chromium with the flags every test needs and `extra`, in a fresh profile directory.
ChromiumRun RunChromium(const std::string& chromium, const std::string& work_dir,
                        const std::string& url, int width, int height, const std::string& extra) {
  std::string profile_template = (fs::path(work_dir) / "chromium-profile-XXXXXX").string();
  ChromiumRun run;
  if (::mkdtemp(profile_template.data()) == nullptr) {
    run.err = "cannot create a profile directory under " + work_dir + ": " + std::strerror(errno);
    return run;
  }
  const fs::path profile = profile_template;
  const fs::path out = profile.string() + ".out", err = profile.string() + ".err";
  // --no-sandbox: tests run as root in containers; SwiftShader gives WebGL without a GPU.
  const std::string command =
      ShellQuote(chromium) +
      " --headless=new --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader"
      " --enable-unsafe-swiftshader --hide-scrollbars --no-first-run --no-default-browser-check"
      " --window-size=" +
      std::to_string(width) + "," + std::to_string(height) +
      " --virtual-time-budget=3000 --user-data-dir=" + ShellQuote(profile.string()) + " " + extra +
      " " + ShellQuote(url) + " >" + ShellQuote(out.string()) + " 2>" + ShellQuote(err.string()) +
      " </dev/null";
  const int status = std::system(command.c_str());
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = ReadAll(out);
  run.err = ReadAll(err);
  std::error_code ignored;
  fs::remove_all(profile, ignored);
  fs::remove(out, ignored);
  fs::remove(err, ignored);
  return run;
}

}  // namespace

bool ReadPng(const std::string& path, RgbImage* image, std::string* error) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    *error = path + ": " + png.message;
    return false;
  }
  png.format = PNG_FORMAT_RGB;
  image->width = static_cast<int>(png.width);
  image->height = static_cast<int>(png.height);
  image->rgb.assign(PNG_IMAGE_SIZE(png), 0);
  if (!png_image_finish_read(&png, nullptr, image->rgb.data(), 0, nullptr)) {
    *error = path + ": " + png.message;
    png_image_free(&png);
    return false;
  }
  return true;
}

std::int64_t DistinctColours(const RgbImage& image, const PixelRegion& region) {
  std::unordered_set<std::uint32_t> colours;
  for (int y = region.y0; y < region.y1; ++y) {
    for (int x = region.x0; x < region.x1; ++x) {
      const auto c = image.at(x, y);
      colours.insert(std::uint32_t{c[0]} << 16 | std::uint32_t{c[1]} << 8 | c[2]);
    }
  }
  return static_cast<std::int64_t>(colours.size());
}

double FractionUnlike(const RgbImage& image, const PixelRegion& region,
                      const std::array<std::uint8_t, 3>& colour, int threshold) {
  std::int64_t unlike = 0, all = 0;
  for (int y = region.y0; y < region.y1; ++y) {
    for (int x = region.x0; x < region.x1; ++x, ++all) {
      const auto c = image.at(x, y);
      unlike += LargestChannelDifference(c.data(), colour.data()) > threshold;
    }
  }
  return all > 0 ? static_cast<double>(unlike) / static_cast<double>(all) : 0.0;
}

double FractionDiffering(const RgbImage& a, const RgbImage& b, const PixelRegion& region,
                         int threshold) {
  if (a.width != b.width || a.height != b.height) return 1.0;
  std::int64_t differing = 0, all = 0;
  for (int y = region.y0; y < region.y1; ++y) {
    for (int x = region.x0; x < region.x1; ++x, ++all) {
      differing += LargestChannelDifference(a.at(x, y).data(), b.at(x, y).data()) > threshold;
    }
  }
  return all > 0 ? static_cast<double>(differing) / static_cast<double>(all) : 0.0;
}

std::string FindChromium() {
  if (const char* given = std::getenv("INSCRIBE_CHROMIUM"); given != nullptr && *given != '\0') {
    return ::access(given, X_OK) == 0 ? given : "";
  }
  const char* path = std::getenv("PATH");
  std::string directories = path != nullptr ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= directories.size()) {
    const std::size_t end = std::min(directories.find(':', start), directories.size());
    const fs::path candidate = fs::path(directories.substr(start, end - start)) / "chromium";
    if (end > start && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return "";
}

ChromiumRun ChromiumScreenshot(const std::string& chromium, const std::string& work_dir,
                               const std::string& url, const std::string& png_path, int width,
                               int height) {
  return RunChromium(chromium, work_dir, url, width, height,
                     "--screenshot=" + ShellQuote(png_path));
}

ChromiumRun ChromiumDumpDom(const std::string& chromium, const std::string& work_dir,
                            const std::string& url, int width, int height) {
  return RunChromium(chromium, work_dir, url, width, height, "--dump-dom");
}

std::string BodyAttribute(const std::string& dom, const std::string& name, bool* found) {
  *found = false;
  const std::size_t body = dom.find("<body");
  if (body == std::string::npos) return "";
  // The tag ends at the first '>' outside a quoted attribute value.
  std::size_t end = body;
  for (char quote = 0; end < dom.size() && (quote != 0 || dom[end] != '>'); ++end) {
    if (quote == 0 && (dom[end] == '"' || dom[end] == '\'')) {
      quote = dom[end];
    } else if (dom[end] == quote) {
      quote = 0;
    }
  }
  const std::string tag = dom.substr(body, end - body);
  const std::string key = " " + name + "=\"";
  const std::size_t at = tag.find(key);
  if (at == std::string::npos) return "";
  const std::size_t value = at + key.size();
  *found = true;
  return tag.substr(value, tag.find('"', value) - value);
}

}  // namespace inscribe::testing
