#include "tools/common/html_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <regex>
#include <string>
#include <vector>

#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"

namespace igi {
namespace {

// Independent of the code under test: RFC 4648 base64 decoding.
std::string Base64Decode(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=') break;
    const size_t v = alphabet.find(c);
    EXPECT_NE(v, std::string::npos) << "bad base64 character " << int(c);
    acc = (acc << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((acc >> bits) & 0xff);
    }
  }
  return out;
}

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + 1)) {
    ++n;
  }
  return n;
}

double Srgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

class HtmlReportTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::UniqueTempDir("igi_html_report_test"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Decodes the index-th embedded PNG of the page back to an image (values in [0, 1]).
  Image EmbeddedImage(const std::string& html, int index) {
    const std::string prefix = "<img src=\"data:image/png;base64,";
    size_t pos = std::string::npos;
    for (int i = 0; i <= index; ++i) {
      pos = html.find(prefix, pos == std::string::npos ? 0 : pos + 1);
      if (pos == std::string::npos) {
        ADD_FAILURE() << "no embedded image " << index;
        return {};
      }
    }
    const size_t begin = pos + prefix.size();
    const std::string b64 = html.substr(begin, html.find('"', begin) - begin);
    const auto path = dir_ / ("embedded" + std::to_string(index) + ".png");
    WriteFileAtomic(path, Base64Decode(b64));
    return ReadImage(path);
  }

  std::filesystem::path dir_;
};

TEST(HtmlEscapeTest, EscapesTheFiveSpecialCharacters) {
  EXPECT_EQ(HtmlEscape("<a href=\"x\">Tom & 'Jerry'</a>"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;");
  EXPECT_EQ(HtmlEscape("plain text, ünïcode"), "plain text, ünïcode");
}

TEST(HtmlEscapeTest, ReportTextIsEscapedEverywhere) {
  HtmlReport report("T<1>");
  report.Heading("<h>");
  report.Paragraph("<script>alert('x')</script>");
  report.Note("a & b", "<bad kind>");
  report.Table({"<th>"}, {{"<td>"}}, {{"bad\" onclick=\"x"}});
  const std::string html = report.Html();
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_EQ(html.find("<bad"), std::string::npos);
  EXPECT_EQ(html.find("\" onclick"), std::string::npos);
  EXPECT_NE(html.find("<title>T&lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<h2>&lt;h&gt;</h2>"), std::string::npos);
  EXPECT_NE(html.find("<div class=\"note info\">a &amp; b</div>"), std::string::npos);
  EXPECT_NE(html.find("<th>&lt;th&gt;</th>"), std::string::npos);
}

TEST(Base64Test, Rfc4648TestVectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  // Bytes >= 0x80 (char is signed here) and the last two alphabet characters.
  EXPECT_EQ(Base64Encode(std::string("\xfb\xff\xbf", 3)), "+/+/");
  EXPECT_EQ(Base64Encode(std::string("\0\0\0", 3)), "AAAA");
}

TEST_F(HtmlReportTest, EmbeddedPngDecodesToTheSrgbMappingOfTheImage) {
  // A 3-channel gradient from 0 to 1.5 (so clamping is exercised), exposure 1.
  Image gradient(16, 8, 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) gradient.at(x, y, c) = 1.5f * float(x + 16 * y + c) / 130.0f;
  HtmlReport report("png");
  report.Image(gradient, "gradient", 1.0);
  const Image decoded = EmbeddedImage(report.Html(), 0);
  ASSERT_EQ(decoded.width, 16);
  ASSERT_EQ(decoded.height, 8);
  ASSERT_EQ(decoded.channels, 3);
  // Tolerance 1/255: one 8-bit quantisation step (rounding gives at most half of it).
  for (size_t i = 0; i < gradient.pixels.size(); ++i) {
    ASSERT_NEAR(decoded.pixels[i], Srgb(gradient.pixels[i]), 1.0 / 255) << "sample " << i;
  }
}

TEST_F(HtmlReportTest, GreyAndRgbaImagesBecomeRgbWithExposureApplied) {
  Image grey(5, 1, 1);
  Image rgba(5, 1, 4);
  for (int x = 0; x < 5; ++x) {
    grey.at(x, 0) = 0.1f * float(x);
    for (int c = 0; c < 4; ++c) rgba.at(x, 0, c) = c == 3 ? 0.0f : 0.05f * float(x + c);
  }
  HtmlReport report("channels");
  report.ImageRow({{grey, "grey"}, {rgba, "rgba"}}, 2.0);
  const std::string html = report.Html();
  EXPECT_NE(html.find("<div class=\"row\">"), std::string::npos);
  const Image g = EmbeddedImage(html, 0);
  const Image r = EmbeddedImage(html, 1);
  ASSERT_EQ(g.channels, 3);
  ASSERT_EQ(r.channels, 3);  // alpha dropped (a zero alpha would otherwise hide the image)
  for (int x = 0; x < 5; ++x) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(g.at(x, 0, c), Srgb(2.0 * grey.at(x, 0)), 1.0 / 255);
      EXPECT_NEAR(r.at(x, 0, c), Srgb(2.0 * rgba.at(x, 0, c)), 1.0 / 255);
    }
  }
}

TEST(ToneMapTest, AutoExposureMapsThe99thPercentileTo0Point9) {
  Image ramp(101, 1, 1);
  for (int x = 0; x <= 100; ++x) ramp.at(x, 0) = float(x);
  ramp.at(0, 0) = std::numeric_limits<float>::quiet_NaN();  // ignored by the percentile
  double used = 0;
  const Image display = ToneMapSrgb(ramp, 0, &used);
  // 100 finite values 1..100: the 99th percentile (nearest rank) is 99 (or 100).
  EXPECT_GE(used, 0.9 / 100 - 1e-12);
  EXPECT_LE(used, 0.9 / 99 + 1e-12);
  EXPECT_NEAR(display.at(50, 0, 1), Srgb(50 * used), 1e-6);
}

TEST_F(HtmlReportTest, NonFinitePixelsAreMagenta) {
  Image image(3, 1, 3, 0.25f);
  image.at(0, 0, 1) = std::numeric_limits<float>::quiet_NaN();
  image.at(2, 0, 2) = std::numeric_limits<float>::infinity();
  Image residual(2, 1, 1, 0.0f);
  residual.at(1, 0) = std::numeric_limits<float>::quiet_NaN();
  HtmlReport report("nan");
  report.Image(image, "with NaN", 0);  // auto exposure must ignore NaN/Inf
  report.ResidualImage(residual, "residual with NaN");
  const std::string html = report.Html();
  const Image a = EmbeddedImage(html, 0);
  const Image b = EmbeddedImage(html, 1);
  for (int x : {0, 2}) {
    EXPECT_EQ(a.at(x, 0, 0), 1.0f);
    EXPECT_EQ(a.at(x, 0, 1), 0.0f);
    EXPECT_EQ(a.at(x, 0, 2), 1.0f);
  }
  EXPECT_NEAR(a.at(1, 0, 1), Srgb(0.9), 1.0 / 255) << "auto exposure maps 0.25 to 0.9";
  EXPECT_EQ(b.at(1, 0, 0), 1.0f);
  EXPECT_EQ(b.at(1, 0, 1), 0.0f);
  EXPECT_EQ(b.at(1, 0, 2), 1.0f);
}

TEST_F(HtmlReportTest, ResidualColourMapIsBlueNegativeWhiteZeroRedPositive) {
  // Channels are averaged: (-3, 0, 0) has mean -1.
  Image residual(4, 1, 3, 0.0f);
  residual.at(0, 0, 0) = -3.0f;
  residual.at(2, 0, 1) = 0.5f;
  for (int c = 0; c < 3; ++c) residual.at(3, 0, c) = 2.0f;  // beyond the scale: clamps to red
  HtmlReport report("residual");
  report.ResidualImage(residual, "residual", 1.0);
  const Image rgb = EmbeddedImage(report.Html(), 0);
  const float kTol = 1.0f / 255;
  auto expect_rgb = [&](int x, float r, float g, float b) {
    EXPECT_NEAR(rgb.at(x, 0, 0), r, kTol) << "x " << x;
    EXPECT_NEAR(rgb.at(x, 0, 1), g, kTol) << "x " << x;
    EXPECT_NEAR(rgb.at(x, 0, 2), b, kTol) << "x " << x;
  };
  expect_rgb(0, 0, 0, 1);                        // -1: blue
  expect_rgb(1, 1, 1, 1);                        // 0: white
  expect_rgb(2, 1, 1 - 0.5f / 3, 1 - 0.5f / 3);  // +1/6: light red
  expect_rgb(3, 1, 0, 0);                        // +2: red
}

TEST_F(HtmlReportTest, WideImagesAreDownsampledToTheDisplayWidth) {
  HtmlReport report("wide");
  report.Image(Image(400, 40, 3, 0.5f), "wide", 1.0, 100);
  const std::string html = report.Html();
  EXPECT_NE(html.find("width=\"100\""), std::string::npos);
  const Image decoded = EmbeddedImage(html, 0);
  EXPECT_EQ(decoded.width, 100);
  EXPECT_EQ(decoded.height, 10);
  EXPECT_NEAR(decoded.at(50, 5, 0), Srgb(0.5), 1.0 / 255);
}

TEST_F(HtmlReportTest, EveryImageHasAltTextAndEmptyImagesDoNotCrash) {
  HtmlReport report("alt");
  report.Image(Image(2, 2, 3, 0.5f), "");
  report.Image(Image(), "nothing");
  report.ResidualImage(Image(), "nothing either");
  report.ImageRow({{Image(2, 2, 1, 0.1f), "a"}, {Image(2, 2, 3, 0.2f), "b"}});
  const std::string html = report.Html();
  EXPECT_EQ(Count(html, "<img "), 3);
  EXPECT_EQ(Count(html, "\" alt=\""), 3);
  EXPECT_EQ(Count(html, "alt=\"\""), 0);
  EXPECT_EQ(Count(html, "(empty image)"), 2);
}

TEST(LinePlotTest, OnePolylinePerSeriesWithItsFinitePoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  HtmlReport report("plot");
  report.LinePlot(
      "cost",
      {{"a", {0, 1, 2, 3, 4}, {5, 4, 3, 2, 1}}, {"b", {0, 1, 2}, {1, nan, 3}}, {"empty", {}, {}}},
      "iteration", "cost");
  const std::string html = report.Html();
  const std::regex polyline("<polyline[^>]* points=\"([^\"]*)\"");
  std::vector<int> counts;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), polyline);
       it != std::sregex_iterator(); ++it) {
    const std::string points = (*it)[1];
    counts.push_back(points.empty() ? 0 : Count(points, ","));
  }
  EXPECT_EQ(counts, (std::vector<int>{5, 2, 0}));
  EXPECT_NE(html.find(">iteration</text>"), std::string::npos);
  EXPECT_NE(html.find(">cost</text>"), std::string::npos);
  EXPECT_NE(html.find("empty (no points)"), std::string::npos);
  // Tick labels: x axis 0..4, y axis 1..5 (steps of 1).
  for (const char* label : {">0</text>", ">2</text>", ">4</text>", ">5</text>"}) {
    EXPECT_NE(html.find(label), std::string::npos) << label;
  }
  EXPECT_EQ(Count(html, "<svg "), 1);
  EXPECT_EQ(Count(html, "</svg>"), 1);
}

TEST(LinePlotTest, LogAxisHasDecadeTicksAndDropsNonPositiveValues) {
  HtmlReport report("log");
  report.LinePlot("residual", {{"r", {1, 2, 3, 4}, {10, 0.1, 0, 0.001}}}, "it", "rms", true);
  const std::string html = report.Html();
  for (const char* label : {">0.001</text>", ">0.01</text>", ">1</text>", ">10</text>"}) {
    EXPECT_NE(html.find(label), std::string::npos) << label;
  }
  const std::smatch m = [&] {
    std::smatch match;
    std::regex_search(html, match, std::regex("points=\"([^\"]*)\""));
    return match;
  }();
  EXPECT_EQ(Count(m[1].str(), ","), 3);  // y = 0 dropped
  EXPECT_NE(html.find(">rms (log)</text>"), std::string::npos);
}

TEST(LinePlotTest, NoSeriesAtAllStillDrawsAxes) {
  HtmlReport report("none");
  report.LinePlot("nothing", {}, "x", "y");
  const std::string html = report.Html();
  EXPECT_EQ(Count(html, "<polyline"), 0);
  EXPECT_NE(html.find("<rect"), std::string::npos);
  EXPECT_NE(html.find(">1</text>"), std::string::npos);
}

TEST_F(HtmlReportTest, WriteIsAtomicAndThePageIsHtml5) {
  HtmlReport report("Run & report");
  report.Paragraph("hello");
  report.Table({"metric", "value"}, {{"rmse", "0.1"}, {"bias", "0.5"}}, {{}, {"", "bad"}});
  const auto path = dir_ / "sub" / "report.html";
  report.Write(path);
  const std::string text = ReadFileToString(path);
  EXPECT_EQ(text, report.Html());
  EXPECT_EQ(text.rfind("<!DOCTYPE html>\n<html lang=\"en\">", 0), 0u);
  EXPECT_NE(text.find("<meta charset=\"utf-8\">"), std::string::npos);
  EXPECT_NE(text.find("<title>Run &amp; report</title>"), std::string::npos);
  EXPECT_NE(text.find("<td class=\"bad\">0.5</td>"), std::string::npos);
  EXPECT_NE(text.find("<td>rmse</td>"), std::string::npos);
  EXPECT_NE(text.find("</html>"), std::string::npos);
  // Only the final file is left (no temporary beside it); a rewrite replaces it whole.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir_ / "sub")) {
    ++files;
  }
  EXPECT_EQ(files, 1);
  HtmlReport other("second");
  other.Write(path);
  EXPECT_EQ(ReadFileToString(path), other.Html());
}

}  // namespace
}  // namespace igi
