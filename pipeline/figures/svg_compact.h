// Making cairo's SVG figures small enough to inline in report.html: shorter numbers and
// polylines, ids prefixed per figure, and, over the whole page, one CSS class per distinct style
// and one shared outline per distinct glyph. Text in, text out; the drawing is unchanged at
// 0.1 px.
#pragma once

#include <string>

namespace bifilar {

// One figure (the text from its "<svg"): every cairo polyline rewritten with the y flip applied
// and relative line-tos, then every number with three or more decimals shortened to one decimal,
// and the style properties that restate SVG defaults dropped.
std::string CompactSvg(const std::string& svg);

// Every id="...", href="#..." and url(#...) of `svg` prefixed with `prefix`, so the glyph and clip
// ids that every cairo SVG names alike do not collide when several figures share one page.
std::string PrefixSvgIds(std::string svg, const std::string& prefix);

// Every style="..." attribute of the page becomes class="sN" with one CSS rule per distinct
// style (inserted before </head>); tags that have a class already keep theirs.
std::string ShareStyles(const std::string& html);

// One <symbol> per distinct glyph outline of the page's inline SVGs, in a hidden SVG before
// </body>, with every figure's <use> pointed at it (ids are document-wide in HTML).
std::string ShareSvgGlyphs(const std::string& html);

}  // namespace bifilar
