#include "inscribe/view/view_report_html.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/synthetic_meshes.h"
#include "viewer_assets.h"

namespace inscribe::view {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Occurrences of `needle` in `haystack`.
int Count(const std::string& haystack, const std::string& needle) {
  int n = 0;
  for (std::size_t at = haystack.find(needle); at != std::string::npos;
       at = haystack.find(needle, at + 1)) {
    ++n;
  }
  return n;
}

// The text of the data element, as the page's script reads it.
std::string DataElementText(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"inscribe-data\">";
  const std::size_t start = html.find(open) + open.size();
  return html.substr(start, html.find("</script>", start) - start);
}

ViewPageFacts SmallFacts(const std::string& title) {
  ViewPageFacts facts;
  facts.title = title;
  facts.mesh_name = "box.off";
  facts.mesh_sha256 = "sha256:00";
  facts.spheres_name = "box.json";
  facts.quality.spheres = 2;
  facts.quality.nerr = 0.25;
  facts.protrusion = {0.0, 0.0123456789};
  facts.boundary_to_envelope = MakeSignedHistogram({-0.1, -0.2, 0.05}, 4, 1e-9);
  facts.envelope_to_boundary = MakeSignedHistogram({-0.3}, 4, 1e-9);
  facts.envelope_area = 3.5;
  return facts;
}

const std::vector<Sphere> kTwoSpheres = {{Vector3(0.5, 0.5, 0.5), 0.123456789},
                                         {Vector3(0.25, 0.3, 1.0 / 3.0), 0.2}};

TEST(ViewReportHtml, DataHoldsTheGeometryRoundedToFloatPrecision) {
  const Mesh box = testing::Box(Vector3::Zero(), Vector3::Ones());
  const nlohmann::json data = ViewPageData(box, kTwoSpheres, SmallFacts("t"));
  EXPECT_EQ(data.at("mesh").at("vertices").size(), 3u * box.num_vertices());
  EXPECT_EQ(data.at("mesh").at("triangles").size(), 3u * box.num_triangles());
  EXPECT_EQ(data.at("mesh").at("bbox").at("max"), nlohmann::json({1.0, 1.0, 1.0}));
  EXPECT_EQ(data.at("spheres").at("count"), 2);
  const auto xyzr = data.at("spheres").at("xyzr").get<std::vector<double>>();
  EXPECT_EQ(xyzr, (std::vector<double>{0.5, 0.5, 0.5, 0.1234568, 0.25, 0.3, 0.3333333, 0.2}));
  EXPECT_EQ(data.at("spheres").at("protrusion"), nlohmann::json({0.0, 0.01235}));
  EXPECT_EQ(data.at("report").at("nerr"), 0.25);
  EXPECT_EQ(data.at("report").at("envelope_area"), 3.5);
  const nlohmann::json& h = data.at("histograms").at("boundary_to_envelope");
  EXPECT_EQ(h.at("counts"), nlohmann::json({1, 1, 1, 0}));  // range 0.2, bins 0.1 wide
  EXPECT_EQ(h.at("edges").size(), 5u);
  EXPECT_EQ(h.at("samples"), 3);
  EXPECT_EQ(data.at("histograms").at("envelope_to_boundary").at("samples"), 1);
}

TEST(ViewReportHtml, PageInlinesEverythingItNeeds) {
  const Mesh box = testing::Box(Vector3::Zero(), Vector3::Ones());
  const absl::StatusOr<std::string> html =
      ViewPageHtml(ViewPageData(box, kTwoSpheres, SmallFacts("box")), "box");
  ASSERT_TRUE(html.ok()) << html.status();
  EXPECT_THAT(*html, HasSubstr(std::string(ThreeJs())));
  EXPECT_THAT(*html, HasSubstr(std::string(OrbitControlsJs())));
  EXPECT_THAT(*html, HasSubstr(std::string(ViewPageJs())));
  EXPECT_THAT(*html, HasSubstr(std::string(ViewPageCss())));
  EXPECT_THAT(*html, HasSubstr(std::string(ThreeJsLicense())));
  EXPECT_GT(ThreeJs().size(), 500'000u);
  EXPECT_THAT(std::string(OrbitControlsJs()), HasSubstr("THREE.OrbitControls"));
  // Four script elements (data, three.js, OrbitControls, the page's), no external reference.
  EXPECT_EQ(Count(*html, "<script"), 4);
  EXPECT_EQ(Count(*html, "</script>"), 4);
  EXPECT_THAT(*html, Not(HasSubstr(" src=")));
  EXPECT_THAT(*html, Not(HasSubstr("<link")));
}

TEST(ViewReportHtml, TextFromTheUserCannotEndItsElement) {
  const Mesh box = testing::Box(Vector3::Zero(), Vector3::Ones());
  // Script and comment endings in any case, in the title and in the file names.
  const std::string title = "a</script><script>alert(1)</SCRIPT>--><!--<b>&\"'";
  ViewPageFacts facts = SmallFacts(title);
  facts.mesh_name = "</Script >mesh.off";
  facts.spheres_name = "<!--spheres.json";
  const absl::StatusOr<std::string> html =
      ViewPageHtml(ViewPageData(box, kTwoSpheres, facts), title);
  ASSERT_TRUE(html.ok()) << html.status();
  EXPECT_EQ(Count(*html, "<script"), 4);
  EXPECT_EQ(Count(*html, "</script>"), 4);
  const std::string text = DataElementText(*html);
  EXPECT_THAT(text, Not(HasSubstr("<")));
  // The script reads back exactly what was given.
  const nlohmann::json data = nlohmann::json::parse(text);
  EXPECT_EQ(data.at("title"), title);
  EXPECT_EQ(data.at("mesh").at("name"), "</Script >mesh.off");
  EXPECT_EQ(data.at("spheres").at("name"), "<!--spheres.json");
  // The tab title is escaped text.
  EXPECT_THAT(*html, HasSubstr("<title>a&lt;/script&gt;&lt;script&gt;alert(1)&lt;/SCRIPT&gt;"
                               "--&gt;&lt;!--&lt;b&gt;&amp;&quot;&#39; - inscribe view</title>"));
}

TEST(ViewReportHtml, InvalidUtf8InNamesIsReplacedNotFatal) {
  const Mesh box = testing::Box(Vector3::Zero(), Vector3::Ones());
  ViewPageFacts facts = SmallFacts("bad \xff\xfe name");
  facts.mesh_name = "m\xc3.off";
  const absl::StatusOr<std::string> html =
      ViewPageHtml(ViewPageData(box, kTwoSpheres, facts), facts.title);
  ASSERT_TRUE(html.ok()) << html.status();
  const nlohmann::json data = nlohmann::json::parse(DataElementText(*html));
  EXPECT_EQ(data.at("title"), "bad \xef\xbf\xbd\xef\xbf\xbd name");  // U+FFFD twice
}

}  // namespace
}  // namespace inscribe::view
