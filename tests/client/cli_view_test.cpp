// `inscribe view`, run as users run it on a real mesh, and its page opened in headless
// Chromium: the page must be self-contained, carry the quality report, and draw the spheres.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "client/cli_run.h"
#include "client/headless_chromium.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

constexpr int kWidth = 800, kHeight = 600;
constexpr int kPanelWidth = 340;                                         // view_page.css #panel
constexpr std::array<std::uint8_t, 3> kBackground = {0xf3, 0xf4, 0xf6};  // view_page.js

// The JSON the page's script reads: <script type="application/json" id="inscribe-data">.
nlohmann::json PageData(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"inscribe-data\">";
  const std::size_t start = html.find(open);
  if (start == std::string::npos) return nullptr;
  const std::size_t end = html.find("</script>", start);
  return nlohmann::json::parse(html.substr(start + open.size(), end - start - open.size()));
}

// Every tag `tag` in `html` that refers to another resource through src= or href=.
std::vector<std::string> ExternalReferences(const std::string& html, const std::string& tag) {
  std::vector<std::string> found;
  for (std::size_t at = html.find(tag); at != std::string::npos; at = html.find(tag, at + 1)) {
    const std::string element = html.substr(at, html.find('>', at) - at);
    if (element.find(" src=") != std::string::npos || element.find(" href=") != std::string::npos) {
      found.push_back(element);
    }
  }
  return found;
}

std::string FileUrl(const fs::path& page, const std::string& options = "") {
  return "file://" + fs::absolute(page).string() + (options.empty() ? "" : "#" + options);
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// Files whose name holds ".tmp.": what an interrupted atomic write would leave.
int TemporaryFiles(const fs::path& dir) {
  int count = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    count += entry.path().filename().string().find(".tmp.") != std::string::npos;
  }
  return count;
}

// One sphere set for bunny00 and its page, made once for the suite (about 5 s).
class CliView : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("inscribe_cli_view_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    bunny_ = testing::TestMeshPath("bunny00.off");
    if (bunny_.empty()) return;
    spheres_ = dir_ / "bunny.json";
    page_ = dir_ / "bunny.html";
    generated_ =
        RunCli("generate " + Quote(bunny_) + " --max-spheres 300 -o " + Quote(spheres_.string()));
    viewed_ = RunCli("view " + Quote(bunny_) + " " + Quote(spheres_.string()) + " -o " +
                     Quote(page_.string()));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("bunny00.off");
    ASSERT_EQ(generated_.exit_code, 0) << generated_.err;
    ASSERT_EQ(viewed_.exit_code, 0) << viewed_.err;
  }

  static std::int64_t SphereCount() {
    return static_cast<std::int64_t>(nlohmann::json::parse(Slurp(spheres_)).at("spheres").size());
  }

  // Fails the test when Debian's chromium is not installed: the page's drawing is what this
  // suite is for, so a missing browser must not pass quietly.
  static std::string Chromium() {
    const std::string chromium = testing::FindChromium();
    EXPECT_FALSE(chromium.empty())
        << "chromium not found on PATH (or $INSCRIBE_CHROMIUM): install Debian's chromium "
           "(apt-get install chromium, as scripts/install-deps does) to test inscribe view";
    return chromium;
  }

  static testing::RgbImage Screenshot(const std::string& chromium, const fs::path& page,
                                      const std::string& options, const std::string& name) {
    const fs::path png = dir_ / name;
    const testing::ChromiumRun run = testing::ChromiumScreenshot(
        chromium, dir_.string(), FileUrl(page, options), png.string(), kWidth, kHeight);
    testing::RgbImage image;
    std::string error;
    EXPECT_TRUE(testing::ReadPng(png.string(), &image, &error))
        << error << "\nchromium exit " << run.exit_code << ":\n"
        << run.err;
    EXPECT_EQ(image.width, kWidth);
    EXPECT_EQ(image.height, kHeight);
    return image;
  }

  static std::string DumpDom(const std::string& chromium, const fs::path& page,
                             const std::string& options = "") {
    const testing::ChromiumRun run =
        testing::ChromiumDumpDom(chromium, dir_.string(), FileUrl(page, options), kWidth, kHeight);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.out;
  }

  inline static fs::path dir_, spheres_, page_;
  inline static std::string bunny_;
  inline static CliRun generated_, viewed_;
};

TEST_F(CliView, WritesOneSelfContainedPage) {
  EXPECT_EQ(viewed_.out, page_.string() + "\n");
  const std::string html = Slurp(page_);
  EXPECT_GT(html.size(), 600'000u);  // three.min.js alone is 600 KB
  EXPECT_THAT(html, HasSubstr("<!DOCTYPE html>"));
  EXPECT_THAT(html, HasSubstr("three.js 0.147.0"));  // the licence comment
  EXPECT_THAT(html, HasSubstr("Permission is hereby granted"));
  for (const std::string tag : {"<script", "<link", "<img", "<iframe", "<object", "<embed"}) {
    const std::vector<std::string> references = ExternalReferences(html, tag);
    EXPECT_TRUE(references.empty()) << tag << " refers out: " << references.front();
  }
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));
  EXPECT_THAT(html, Not(HasSubstr("href=\"http")));
  EXPECT_EQ(TemporaryFiles(dir_), 0);
}

TEST_F(CliView, PageCarriesTheQualityReportAndBothHistograms) {
  const nlohmann::json data = PageData(Slurp(page_));
  ASSERT_TRUE(data.is_object());
  const std::int64_t n = SphereCount();
  EXPECT_EQ(data.at("spheres").at("count").get<std::int64_t>(), n);
  EXPECT_EQ(data.at("spheres").at("xyzr").size(), static_cast<std::size_t>(4 * n));
  EXPECT_EQ(data.at("spheres").at("protrusion").size(), static_cast<std::size_t>(n));
  EXPECT_EQ(data.at("mesh").at("vertices").size(), 3u * 37706);
  EXPECT_EQ(data.at("mesh").at("triangles").size(), 3u * 75408);

  // The panel's figures are `inscribe evaluate`'s, for the same samples.
  const CliRun evaluated = RunCli("evaluate --json " + Quote(bunny_) + " " + Quote(spheres_));
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  const nlohmann::json expected = nlohmann::json::parse(evaluated.out);
  const nlohmann::json& report = data.at("report");
  for (const char* key : {"spheres", "nerr", "protrusion_max", "coverage",
                          "boundary_to_union_hausdorff", "surface_samples"}) {
    EXPECT_EQ(report.at(key), expected.at(key)) << key;
  }

  // Internal spheres tangent to the boundary (S_D): both directions <= 0 up to rounding
  // (Fig. 7's first row), and boundary -> envelope is the boundary's distance to the union.
  const double diagonal = expected.at("bbox_diagonal").get<double>();
  for (const char* direction : {"boundary_to_envelope", "envelope_to_boundary"}) {
    SCOPED_TRACE(direction);
    const nlohmann::json& h = data.at("histograms").at(direction);
    const auto counts = h.at("counts").get<std::vector<std::int64_t>>();
    const auto edges = h.at("edges").get<std::vector<double>>();
    EXPECT_EQ(counts.size() + 1, edges.size());
    std::int64_t total = 0;
    for (std::int64_t c : counts) total += c;
    EXPECT_EQ(total, 100'000);
    EXPECT_EQ(h.at("samples").get<std::int64_t>(), 100'000);
    EXPECT_LE(h.at("max").get<double>(), 1e-9 * diagonal);
    EXPECT_LT(h.at("min").get<double>(), 0.0);
    EXPECT_NEAR(h.at("mean_absolute").get<double>(), -h.at("mean").get<double>(), 1e-9 * diagonal);
    EXPECT_GT(h.at("mean_absolute").get<double>(), 1e-4 * diagonal);
    EXPECT_LT(h.at("mean_absolute").get<double>(), 0.02 * diagonal);
  }
  EXPECT_NEAR(data.at("histograms").at("boundary_to_envelope").at("mean_absolute").get<double>(),
              expected.at("boundary_to_union_mean").get<double>(), 1e-9 * diagonal);
}

TEST_F(CliView, HeadlessChromiumDrawsMeshSpheresAndPanel) {
  const std::string chromium = Chromium();
  ASSERT_FALSE(chromium.empty());
  const testing::PixelRegion viewport = {kPanelWidth + 10, 0, kWidth, kHeight};

  const testing::RgbImage page = Screenshot(chromium, page_, "", "page.png");
  ASSERT_EQ(page.width, kWidth);
  EXPECT_EQ(page.at(kWidth - 3, 3), kBackground);
  // Not blank: the model covers a good part of the view, shaded in many colours.
  EXPECT_GT(testing::DistinctColours(page, viewport), 500);
  EXPECT_GT(testing::FractionUnlike(page, viewport, kBackground, 8), 0.15);
  // The panel holds text and histograms (dark ink on white).
  const testing::PixelRegion panel = {0, 0, kPanelWidth - 10, kHeight};
  EXPECT_GT(testing::FractionUnlike(page, panel, {255, 255, 255}, 60), 0.02);

  // Spheres alone, then nothing: the spheres account for the difference.
  const testing::RgbImage spheres = Screenshot(chromium, page_, "panel=0&mesh=0", "spheres.png");
  const testing::RgbImage empty =
      Screenshot(chromium, page_, "panel=0&mesh=0&spheres=0", "empty.png");
  ASSERT_EQ(spheres.width, kWidth);
  ASSERT_EQ(empty.width, kWidth);
  const testing::PixelRegion all = testing::WholeImage(spheres);
  EXPECT_LT(testing::FractionUnlike(empty, all, kBackground, 8), 0.001);
  EXPECT_GT(testing::FractionUnlike(spheres, all, kBackground, 8), 0.15);
  EXPECT_GT(testing::FractionDiffering(spheres, empty, all, 8), 0.15);
  EXPECT_GT(testing::DistinctColours(spheres, all), 500);

  // Colour by protrusion: none of these spheres protrudes, so all turn grey.
  const testing::RgbImage grey =
      Screenshot(chromium, page_, "panel=0&mesh=0&color=protrusion", "grey.png");
  ASSERT_EQ(grey.width, kWidth);
  EXPECT_GT(testing::FractionDiffering(grey, spheres, all, 24), 0.1);
}

TEST_F(CliView, PageReportsSpheresDrawnAndNoError) {
  const std::string chromium = Chromium();
  ASSERT_FALSE(chromium.empty());
  bool found = false;
  const std::string dom = DumpDom(chromium, page_);
  EXPECT_EQ(testing::BodyAttribute(dom, "data-spheres-drawn", &found),
            std::to_string(SphereCount()));
  EXPECT_TRUE(found) << dom.substr(0, 2000);
  const std::string error = testing::BodyAttribute(dom, "data-error", &found);
  EXPECT_FALSE(found) << error;
  EXPECT_THAT(dom, HasSubstr("(rendered)</title>"));

  const std::string hidden = DumpDom(chromium, page_, "spheres=0");
  EXPECT_EQ(testing::BodyAttribute(hidden, "data-spheres-drawn", &found), "0");
  EXPECT_TRUE(found);
}

TEST_F(CliView, TitleCannotBreakOutOfThePage) {
  const std::string chromium = Chromium();
  ASSERT_FALSE(chromium.empty());
  const std::string title =
      "</script><script>document.body.dataset.error=\"injected\"</script><!-- & \"quotes\"";
  const fs::path page = dir_ / "title.html";
  const CliRun run =
      RunCli("view " + Quote(bunny_) + " " + Quote(spheres_.string()) + " --samples 1000 -o " +
             Quote(page.string()) + " --title " + Quote(title));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string html = Slurp(page);
  EXPECT_EQ(PageData(html).at("title"), title);
  EXPECT_THAT(html, HasSubstr("<title>&lt;/script&gt;&lt;script&gt;"));
  bool found = false;
  const std::string dom = DumpDom(chromium, page);
  const std::string error = testing::BodyAttribute(dom, "data-error", &found);
  EXPECT_FALSE(found) << error;
  EXPECT_EQ(testing::BodyAttribute(dom, "data-spheres-drawn", &found),
            std::to_string(SphereCount()));
}

TEST_F(CliView, ReadsEverySphereFormatTheProjectReads) {
  // Written by generate in each format, read back by view: the same spheres.
  const std::int64_t n = SphereCount();
  for (const std::string extension : {"sph", "csv", "yml"}) {
    SCOPED_TRACE(extension);
    const fs::path file = dir_ / ("bunny." + extension);
    ASSERT_EQ(RunCli("generate " + Quote(bunny_) + " --max-spheres 300 --link body -o " +
                     Quote(file.string()))
                  .exit_code,
              0);
    const fs::path page = dir_ / ("bunny-" + extension + ".html");
    const CliRun run = RunCli("view " + Quote(bunny_) + " " + Quote(file.string()) +
                              " --samples 1000 -o " + Quote(page.string()));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(PageData(Slurp(page)).at("spheres").at("count").get<std::int64_t>(), n);
  }
  // .sph: level 0 is the one root sphere; a level past the tree is an error naming it.
  const std::string sph = Quote((dir_ / "bunny.sph").string());
  const fs::path root = dir_ / "root.html";
  CliRun run = RunCli("view " + Quote(bunny_) + " " + sph + " --sph-level 0 --samples 1000 -o " +
                      Quote(root.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(PageData(Slurp(root)).at("spheres").at("count"), 1);
  run = RunCli("view " + Quote(bunny_) + " " + sph + " --sph-level 7 -o " + Quote(root.string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("level 7"));

  // cuRobo YAML with two links: --link picks one; without it the error lists them.
  const fs::path robot = dir_ / "robot.yml";
  WriteText(robot,
            "collision_spheres:\n"
            "  base:\n"
            "    - center: [0.0, 0.0, 0.0]\n"
            "      radius: 0.2\n"
            "  ear:\n"
            "    - center: [0.0, 0.1, 0.0]\n"
            "      radius: 0.1\n"
            "    - center: [0.1, 0.0, 0.0]\n"
            "      radius: 0.1\n");
  const fs::path ear = dir_ / "ear.html";
  run = RunCli("view " + Quote(bunny_) + " " + Quote(robot.string()) +
               " --link ear --samples 1000 -o " + Quote(ear.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(PageData(Slurp(ear)).at("spheres").at("count"), 2);
  run =
      RunCli("view " + Quote(bunny_) + " " + Quote(robot.string()) + " -o " + Quote(ear.string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("base"));
  EXPECT_THAT(run.err, HasSubstr("ear"));
}

TEST_F(CliView, BadInputIsAClearErrorAndWritesNothing) {
  const fs::path bad = dir_ / "bad";
  fs::create_directories(bad);
  const fs::path out = bad / "page.html";
  const std::string mesh = Quote(bunny_), spheres = Quote(spheres_.string());
  const std::string to_out = " -o " + Quote(out.string());
  WriteText(bad / "broken.off", "OFF\n3 1 0\n0 0 0\n1 0\n");
  WriteText(bad / "broken.json", "{\"spheres\": [[0, 0,");
  WriteText(bad / "empty.csv", "x,y,z,r\n");
  WriteText(bad / "a-file", "");
  struct Case {
    std::string args;
    int exit_code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {Quote((bad / "missing.off").string()) + " " + spheres + to_out, 2, "missing.off"},
      {Quote((bad / "broken.off").string()) + " " + spheres + to_out, 2, "broken.off"},
      {mesh + " " + Quote((bad / "missing.json").string()) + to_out, 2, "missing.json"},
      {mesh + " " + Quote((bad / "broken.json").string()) + to_out, 2, "broken.json"},
      {mesh + " " + Quote((bad / "empty.csv").string()) + to_out, 2, "no spheres"},
      {mesh + " " + spheres + " -o " + Quote((bad / "no-such-dir" / "page.html").string()), 2,
       "no-such-dir does not exist"},
      {mesh + " " + spheres + " -o " + Quote((bad / "a-file" / "page.html").string()), 2,
       "is not a directory"},
      {mesh + " " + spheres + " -o " + Quote(bad.string()), 2, "is a directory"},
      {mesh + " " + spheres + " -o " + spheres, 64, "overwrite the sphere file"},
      {mesh + " " + spheres + " --samples 0" + to_out, 64, "samples"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CliRun run = RunCli("view " + c.args);
    EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message));
    EXPECT_EQ(run.out, "");
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(TemporaryFiles(bad), 0);
  EXPECT_EQ(TemporaryFiles(dir_), 0);
  EXPECT_NE(Slurp(spheres_).find("\"spheres\""), std::string::npos);  // left as it was
}

}  // namespace
}  // namespace inscribe
