// The SVG compaction of report.html (pipeline/figures/svg_compact.h): polylines with the y flip
// applied and relative line-tos, numbers shortened to 0.1 px, ids prefixed per figure, styles
// and glyph outlines shared over the page.
#include "pipeline/figures/svg_compact.h"

#include <string>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

TEST(SvgCompact, PolylineGetsTheFlipAppliedAndRelativeLineTos) {
  const std::string svg =
      "<svg><path style=\"fill:none;stroke-opacity:1;\" d=\"M 1.04 2 L 3.5 2.25 L 3.5 1\" "
      "transform=\"matrix(1,0,0,-1,0,10)\"/></svg>";
  // (1.04, 10-2) -> M1 8; (3.5, 7.75) -> +2.5 -.2 (7.75 rounds to 7.8); (3.5, 9) -> +0 +1.2.
  EXPECT_EQ(CompactSvg(svg), "<svg><path style=\"fill:none;\" d=\"M1 8l2.5-.2 0 1.2\"/></svg>");
}

TEST(SvgCompact, CurvesAndOtherTransformsAreLeftAlone) {
  const std::string curve = "<svg><path d=\"M 1 2 C 3 4 5 6 7 8\"/></svg>";
  EXPECT_EQ(CompactSvg(curve), curve);
  const std::string moved = "<svg><path d=\"M 1 2 L 3 4\" transform=\"translate(1,2)\"/></svg>";
  EXPECT_EQ(CompactSvg(moved), moved);
}

TEST(SvgCompact, LongNumbersShortenToOneDecimalWithoutMinusZero) {
  EXPECT_EQ(CompactSvg("<rect x=\"12.345678\" y=\"-0.04321\" width=\"1.25\"/>"),
            "<rect x=\"12.3\" y=\"0\" width=\"1.25\"/>");
}

TEST(SvgCompact, IdsReferencesAndUrlsArePrefixed) {
  EXPECT_EQ(PrefixSvgIds("<g id=\"a\"><use href=\"#a\"/><path clip-path=\"url(#c)\"/></g>", "f0-"),
            "<g id=\"f0-a\"><use href=\"#f0-a\"/><path clip-path=\"url(#f0-c)\"/></g>");
}

TEST(SvgCompact, StylesBecomeSharedClasses) {
  const std::string html =
      "<html><head></head><body><p style=\"x\">a</p><p style=\"x\">b</p>"
      "<p class=\"k\" style=\"y\">c</p></body></html>";
  EXPECT_EQ(ShareStyles(html),
            "<html><head><style>\n.s0{x}\n</style>\n</head><body><p class=\"s0\">a</p>"
            "<p class=\"s0\">b</p><p class=\"k\" style=\"y\">c</p></body></html>");
  EXPECT_EQ(ShareStyles("<p>no style</p>"), "<p>no style</p>");
}

TEST(SvgCompact, EqualGlyphsOfTwoFiguresShareOneSymbol) {
  const std::string html =
      "<body><svg><symbol overflow=\"visible\" id=\"f0-g1\"><path d=\"A\"/></symbol>"
      "<use href=\"#f0-g1\"/></svg><svg><symbol overflow=\"visible\" id=\"f1-g1\"><path d=\"A\"/>"
      "</symbol><use href=\"#f1-g1\"/></svg></body>";
  EXPECT_EQ(
      ShareSvgGlyphs(html),
      "<body><svg><use href=\"#sg0\"/></svg><svg><use href=\"#sg0\"/></svg>"
      "<svg width=\"0\" height=\"0\" style=\"position:absolute\" aria-hidden=\"true\"><defs>\n"
      "<symbol overflow=\"visible\" id=\"sg0\"><path d=\"A\"/></symbol>\n</defs></svg>\n"
      "</body>");
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// PLplot's own svg driver (issue 25): the flip applied, polylines of one style joined in one
// path (a one-point polyline a dot), text as UTF-8 at page coordinates, the whole-page clip
// dropped; a second pass changes nothing.
TEST(SvgCompact, PlplotSvgDriverOutput) {
  const std::string svg =
      "<?xml version=\"1.0\"?>\n<svg\n  xmlns=\"http://www.w3.org/2000/svg\"\n  width=\"100pt\"\n"
      "  height=\"50pt\"\n  viewBox=\"0 0 100 50\"\n  >\n  <rect\n    x=\"0\"\n    y=\"0\"\n"
      "    width=\"100\"\n    height=\"50\"\n    stroke=\"none\"\n    fill=\"#FFFFFF\"\n    />\n"
      "  <g\n    transform=\"matrix(1 0 0 -1 0 50)\"\n    >\n"
      "    <polyline\n      stroke-width=\"1.000000e+00\"\n      stroke=\"#000000\"\n"
      "      stroke-opacity=\"1.000000\"\n      fill=\"none\"\n      points=\"10.00,10.00 "
      "20.04,10.00\"\n      />\n"
      "    <polyline\n      stroke-width=\"1.000000e+00\"\n      stroke=\"#000000\"\n"
      "      stroke-opacity=\"1.000000\"\n      fill=\"none\"\n      points=\"30.00,40.00 "
      "30.00,40.00\"\n      />\n"
      "    <clipPath\n      id=\"text-clipping0\"\n      >\n      <polygon\n"
      "        points=\"0.000000,0.000000 0.000000,49.99 100.000000,49.99 100.000000,0.000000\"\n"
      "        />\n    </clipPath>\n    <g\n      clip-path=\"url(#text-clipping0)\"\n      >\n"
      "      <text\n        dominant-baseline=\"no-change\"\n        fill=\"#000000\"\n"
      "        fill-opacity=\"1.000000\"\n        xml:space=\"preserve\"\n        "
      "font-size=\"17\"\n"
      "        transform=\"matrix(1.000000 0.000000 0.000000 -1.000000 50.000000 5.000000)\"\n"
      "        text-anchor=\"middle\"\n        x=\"0.000000\"\n        y=\"6.640507\"\n"
      "><tspan font-family=\"sans-serif\" font-style=\"normal\" font-weight=\"normal\">"
      "&#x49;&#x20;&#xb1;&#x20;&#x3c3;&#x3c;</tspan></text>\n    </g>\n  </g>\n</svg>\n";
  const std::string out = CompactSvg(svg);
  EXPECT_NE(out.find("viewBox=\"0 0 100 50\""), std::string::npos) << out;
  EXPECT_NE(out.find("width=\"100\" height=\"50\""), std::string::npos) << out;
  // (10, 50-10) -> (20, 40): one path with the dot (30, 10) as its second sub-path.
  EXPECT_NE(out.find("<path fill=\"none\" stroke=\"#000000\" stroke-width=\"1\" "
                     "d=\"M10 40l10 0M30 10l0 0\"/>"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("<text x=\"50\" y=\"51.6\" font-size=\"17\" text-anchor=\"middle\" "
                     "xml:space=\"preserve\"><tspan>I ± σ&lt;</tspan></text>"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("clip"), std::string::npos) << out;
  EXPECT_EQ(out.find("<polyline"), std::string::npos) << out;
  EXPECT_EQ(CompactSvg(out), out);
}

}  // namespace
}  // namespace bifilar
