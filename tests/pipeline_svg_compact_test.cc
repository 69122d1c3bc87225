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
  EXPECT_EQ(ShareSvgGlyphs(html),
            "<body><svg><use href=\"#sg0\"/></svg><svg><use href=\"#sg0\"/></svg>"
            "<svg width=\"0\" height=\"0\" style=\"position:absolute\" aria-hidden=\"true\"><defs>\n"
            "<symbol overflow=\"visible\" id=\"sg0\"><path d=\"A\"/></symbol>\n</defs></svg>\n"
            "</body>");
}

}  // namespace
}  // namespace bifilar
