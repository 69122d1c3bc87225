#include "pipeline/figures/svg_compact.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>

namespace bifilar {
namespace {

// Replaces every occurrence of `from` in `text` by `to`.
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// Shortens every number with three or more decimals in `svg` to one decimal (0.1 px on a 640 px
// page, finer than a screen pixel of the 540 px thumbnails; glyph outlines are in px too) and
// drops the style properties that only restate SVG defaults. Cairo writes 6 decimals.
std::string SimplifySvgNumbers(const std::string& svg) {
  std::string out;
  out.reserve(svg.size());
  const size_t n = svg.size();
  auto digit = [&](size_t i) { return i < n && svg[i] >= '0' && svg[i] <= '9'; };
  for (size_t i = 0; i < n;) {
    const bool starts =
        digit(i) && (i == 0 || !(std::isalnum(static_cast<unsigned char>(svg[i - 1])) ||
                                 svg[i - 1] == '.' || svg[i - 1] == '_'));
    if (!starts) {
      out += svg[i++];
      continue;
    }
    size_t j = i;
    while (digit(j)) ++j;
    size_t decimals = 0;
    if (j < n && svg[j] == '.') {
      size_t k = j + 1;
      while (digit(k)) ++k;
      decimals = k - j - 1;
      if (decimals >= 3) {
        const bool negative = !out.empty() && out.back() == '-';
        double value = std::strtod(svg.substr(i, k - i).c_str(), nullptr);
        char buffer[64];
        std::snprintf(buffer, sizeof(buffer), "%.1f", value);
        std::string text = buffer;
        if (text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0)
          text.resize(text.size() - 2);
        if (negative && text == "0") out.pop_back();  // "-0.04" -> "0", not "-0"
        out += text;
        i = k;
        continue;
      }
      j = k;
    }
    out.append(svg, i, j - i);
    i = j;
  }
  for (const char* redundant :
       {"stroke-opacity:1;", "fill-opacity:1;", "stroke-miterlimit:10;", "fill-rule:nonzero;"}) {
    out = ReplaceAll(out, redundant, "");
  }
  return out;
}

// A number as short as SVG allows at 0.1 px: "12.3", "-4", ".5".
std::string ShortNumber(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.1f", value);
  std::string text = buffer;
  if (text == "-0.0") text = "0.0";
  if (text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0) text.resize(text.size() - 2);
  if (text.rfind("0.", 0) == 0) text.erase(0, 1);
  if (text.rfind("-0.", 0) == 0) text.erase(1, 1);
  return text;
}

// A cairo polyline `<path ... d="M x y L x y ..." transform="matrix(1,0,0,-1,0,H)"/>` rewritten
// with the flip applied and relative line-tos ("M x y l dx dy dx dy ..."), every point rounded
// to 0.1 px first so the sums do not drift; other paths come back unchanged. About half the
// bytes of a long line.
std::string CompactPolyline(const std::string& tag) {
  const size_t d_at = tag.find(" d=\"");
  if (d_at == std::string::npos) return tag;
  const size_t d_end = tag.find('"', d_at + 4);
  if (d_end == std::string::npos) return tag;
  double flip_height = NAN;
  size_t tr_at = tag.find(" transform=\"matrix(1,0,0,-1,0,");
  size_t tr_end = std::string::npos;
  if (tr_at != std::string::npos) {
    const size_t num = tr_at + std::string(" transform=\"matrix(1,0,0,-1,0,").size();
    char* stop = nullptr;
    flip_height = std::strtod(tag.c_str() + num, &stop);
    if (stop == nullptr || std::string(stop, std::min<size_t>(2, std::strlen(stop))) != ")\"")
      return tag;
    tr_end = static_cast<size_t>(stop - tag.c_str()) + 2;
  } else if (tag.find(" transform=") != std::string::npos) {
    return tag;
  }
  std::istringstream in(tag.substr(d_at + 4, d_end - d_at - 4));
  std::string token, d;
  long px = 0, py = 0;
  bool first = true;
  while (in >> token) {
    if (token != (first ? "M" : "L")) return tag;  // curves, several sub-paths: leave as is
    double x = NAN, y = NAN;
    if (!(in >> x >> y) || !std::isfinite(x) || !std::isfinite(y)) return tag;
    if (std::isfinite(flip_height)) y = flip_height - y;
    const long qx = std::lround(10.0 * x), qy = std::lround(10.0 * y);
    if (first) {
      d = "M" + ShortNumber(qx / 10.0) + " " + ShortNumber(qy / 10.0) + "l";
    } else {
      const std::string dx = ShortNumber((qx - px) / 10.0), dy = ShortNumber((qy - py) / 10.0);
      if (d.back() != 'l' && dx[0] != '-') d += ' ';
      d += dx;
      if (dy[0] != '-') d += ' ';
      d += dy;
    }
    px = qx;
    py = qy;
    first = false;
  }
  if (first) return tag;
  if (d.back() == 'l') d.pop_back();
  std::string out = tag;
  if (tr_end != std::string::npos) out.erase(tr_at, tr_end - tr_at);
  return out.replace(d_at + 4, d_end - d_at - 4, d);
}

// Every <path .../> of `svg` through CompactPolyline.
std::string CompactSvgPaths(const std::string& svg) {
  std::string out;
  out.reserve(svg.size());
  size_t at = 0;
  for (size_t start = svg.find("<path ", at); start != std::string::npos;
       start = svg.find("<path ", at)) {
    const size_t end = svg.find('>', start);
    if (end == std::string::npos) break;
    out.append(svg, at, start - at);
    out += CompactPolyline(svg.substr(start, end + 1 - start));
    at = end + 1;
  }
  out.append(svg, at, std::string::npos);
  return out;
}
}  // namespace

std::string CompactSvg(const std::string& svg) { return SimplifySvgNumbers(CompactSvgPaths(svg)); }

std::string PrefixSvgIds(std::string svg, const std::string& prefix) {
  svg = ReplaceAll(svg, "id=\"", "id=\"" + prefix);
  svg = ReplaceAll(svg, "href=\"#", "href=\"#" + prefix);
  svg = ReplaceAll(svg, "url(#", "url(#" + prefix);
  return svg;
}

// Every style="..." attribute of the page (cairo repeats the same few on each element) becomes
// class="sN" with one CSS rule per distinct style; tags that have a class already keep theirs.
std::string ShareStyles(const std::string& html) {
  std::map<std::string, std::string> classes;
  std::string out, css;
  out.reserve(html.size());
  const std::string attr = " style=\"";
  size_t at = 0;
  for (size_t hit = html.find(attr); hit != std::string::npos; hit = html.find(attr, at)) {
    const size_t value = hit + attr.size(), value_end = html.find('"', value);
    if (value_end == std::string::npos) break;
    const size_t tag_start = html.rfind('<', hit), tag_end = html.find('>', hit);
    const std::string tag = html.substr(tag_start, tag_end - tag_start);
    if (tag_start == std::string::npos || tag.find(" class=\"") != std::string::npos) {
      out.append(html, at, value_end + 1 - at);
      at = value_end + 1;
      continue;
    }
    const std::string style = html.substr(value, value_end - value);
    auto it = classes.find(style);
    if (it == classes.end()) {
      it = classes.emplace(style, "s" + std::to_string(classes.size())).first;
      css += "." + it->second + "{" + style + "}\n";
    }
    out.append(html, at, hit - at);
    out += " class=\"" + it->second + "\"";
    at = value_end + 1;
  }
  out.append(html, at, std::string::npos);
  if (classes.empty()) return html;
  const size_t head = out.find("</head>");
  out.insert(head == std::string::npos ? 0 : head, "<style>\n" + css + "</style>\n");
  return out;
}

// Every inline SVG of the page defines its own outline of each glyph (cairo writes text as
// paths): the same digit and letter over a hundred times. This keeps one <symbol> per distinct
// outline, in a hidden SVG at the end of the page, and points every figure's <use> at it (ids
// are document-wide in HTML). The figures' own ids were made unique by Figure()'s prefixes.
std::string ShareSvgGlyphs(const std::string& html) {
  std::map<std::string, std::string> by_content;  // symbol text without its id -> shared id
  std::map<std::string, std::string> renamed;     // a figure's glyph id -> shared id
  std::string shared, body;
  body.reserve(html.size());
  size_t at = 0;
  while (true) {
    const size_t start = html.find("<symbol", at);
    const size_t end = start == std::string::npos ? start : html.find("</symbol>", start);
    if (start == std::string::npos || end == std::string::npos) break;
    const size_t stop = end + std::string("</symbol>").size();
    std::string symbol = html.substr(start, stop - start);
    const size_t id_at = symbol.find(" id=\"");
    const size_t id_end = id_at == std::string::npos ? id_at : symbol.find('"', id_at + 5);
    if (id_end == std::string::npos) {  // not a cairo glyph: leave it where it is
      body.append(html, at, stop - at);
      at = stop;
      continue;
    }
    const std::string id = symbol.substr(id_at + 5, id_end - id_at - 5);
    std::string key = symbol;
    key.erase(id_at, id_end + 1 - id_at);
    auto found = by_content.find(key);
    if (found == by_content.end()) {
      const std::string shared_id = "sg" + std::to_string(by_content.size());
      found = by_content.emplace(key, shared_id).first;
      shared +=
          symbol.substr(0, id_at) + " id=\"" + shared_id + "\"" + symbol.substr(id_end + 1) + "\n";
    }
    renamed[id] = found->second;
    body.append(html, at, start - at);
    at = stop;
  }
  body.append(html, at, std::string::npos);
  if (renamed.empty()) return html;
  std::string out;
  out.reserve(body.size() + shared.size());
  const std::string href = "href=\"#";
  at = 0;
  for (size_t hit = body.find(href); hit != std::string::npos; hit = body.find(href, at)) {
    const size_t id_start = hit + href.size(), id_end = body.find('"', id_start);
    if (id_end == std::string::npos) break;
    out.append(body, at, id_start - at);
    const auto it = renamed.find(body.substr(id_start, id_end - id_start));
    out += it != renamed.end() ? it->second : body.substr(id_start, id_end - id_start);
    at = id_end;
  }
  out.append(body, at, std::string::npos);
  const std::string defs =
      "<svg width=\"0\" height=\"0\" style=\"position:absolute\" aria-hidden=\"true\"><defs>\n" +
      shared + "</defs></svg>\n";
  const size_t close = out.rfind("</body>");
  out.insert(close == std::string::npos ? out.size() : close, defs);
  return out;
}

}  // namespace bifilar
