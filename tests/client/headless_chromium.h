// Headless Chromium (Debian's `chromium`) for tests of the pages `inscribe view` writes:
// screenshots decoded with libpng, and the DOM after the page's scripts ran. WebGL runs on
// SwiftShader (ANGLE's CPU renderer), so no GPU or display is needed.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace inscribe::testing {

// An 8-bit RGB image, rows top to bottom.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3 bytes

  std::array<std::uint8_t, 3> at(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Decodes the PNG at `path` (any colour type; alpha is composited on black by libpng's
// simplified API). On failure returns false with the reason in *error.
bool ReadPng(const std::string& path, RgbImage* image, std::string* error);

// A region of an image: columns [x0, x1), rows [y0, y1).
struct PixelRegion {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
inline PixelRegion WholeImage(const RgbImage& image) { return {0, 0, image.width, image.height}; }

// Distinct RGB triples in `region`.
std::int64_t DistinctColours(const RgbImage& image, const PixelRegion& region);

// Fraction of the pixels of `region` whose largest channel difference from `colour`
// (or, in the second form, from the same pixel of `other`, of the same size) exceeds
// `threshold`.
double FractionUnlike(const RgbImage& image, const PixelRegion& region,
                      const std::array<std::uint8_t, 3>& colour, int threshold);
double FractionDiffering(const RgbImage& a, const RgbImage& b, const PixelRegion& region,
                         int threshold);

// The chromium binary: $INSCRIBE_CHROMIUM if set, else `chromium` on PATH; "" if none.
std::string FindChromium();

struct ChromiumRun {
  int exit_code = -1;
  std::string out;  // stdout: the DOM for DumpDom
  std::string err;  // stderr, for failure messages
};

// Opens `url` (e.g. file:///tmp/x.html#mesh=0) in a window of width x height CSS pixels, lets
// its scripts run for 3 s of virtual time, then writes a screenshot to `png_path`. Each call
// uses a fresh profile directory under `work_dir`, removed afterwards.
ChromiumRun ChromiumScreenshot(const std::string& chromium, const std::string& work_dir,
                               const std::string& url, const std::string& png_path, int width,
                               int height);

// The same, printing the serialised DOM on stdout instead (`--dump-dom`).
ChromiumRun ChromiumDumpDom(const std::string& chromium, const std::string& work_dir,
                            const std::string& url, int width, int height);

// The value of attribute `name` on the DOM's <body> element (the first "<body" tag), or "" and
// *found = false when it has none. Entities are not decoded.
std::string BodyAttribute(const std::string& dom, const std::string& name, bool* found);

}  // namespace inscribe::testing
