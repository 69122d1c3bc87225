#include "pipeline/figures/svg_compact.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <vector>

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

// SimplifySvgNumbers inside the tags of `svg` (attributes: coordinates, path data) and never in
// the words drawn: a title "0.05018 ± 0.00066" or a tick "3.5221" shortened to one decimal read
// "0.1 ± 0" and "3.5" (issue 32). A figure compacted twice (by WriteFigure, then by the report)
// keeps its text.
std::string SimplifyTagNumbers(const std::string& svg) {
  std::string out;
  out.reserve(svg.size());
  for (size_t at = 0; at < svg.size();) {
    const size_t open = svg.find('<', at);
    if (open == std::string::npos) {
      out.append(svg, at, std::string::npos);
      break;
    }
    out.append(svg, at, open - at);
    const size_t close = svg.find('>', open);
    const size_t end = close == std::string::npos ? svg.size() : close + 1;
    out += SimplifySvgNumbers(svg.substr(open, end - open));
    at = end;
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

// Appends point (qx, qy), in tenths of a pixel, to the path `d`: "Mx yl" for the first point,
// then the relative step from the last (*px, *py), without the blanks a sign makes redundant.
void AppendPathPoint(long qx, long qy, bool first, long* px, long* py, std::string* d) {
  if (first) {
    *d = "M" + ShortNumber(qx / 10.0) + " " + ShortNumber(qy / 10.0) + "l";
  } else {
    const std::string dx = ShortNumber((qx - *px) / 10.0), dy = ShortNumber((qy - *py) / 10.0);
    if (d->back() != 'l' && dx[0] != '-') *d += ' ';
    *d += dx;
    if (dy[0] != '-') *d += ' ';
    *d += dy;
  }
  *px = qx;
  *py = qy;
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
    AppendPathPoint(std::lround(10.0 * x), std::lround(10.0 * y), first, &px, &py, &d);
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
// --- PLplot's own SVG driver ("svg"): text as <text>, shapes as <polyline>, all inside one
// <g transform="matrix(1 0 0 -1 0 H)">.

// The attributes of one tag (`tag` from '<' to '>'), name -> value.
std::map<std::string, std::string> Attributes(const std::string& tag) {
  std::map<std::string, std::string> out;
  size_t at = tag.find_first_of(" \t\r\n");
  while (at != std::string::npos && at < tag.size()) {
    const size_t name_start = tag.find_first_not_of(" \t\r\n", at);
    if (name_start == std::string::npos) break;
    const size_t eq = tag.find('=', name_start);
    if (eq == std::string::npos || tag[eq + 1] != '"') break;
    const size_t value_end = tag.find('"', eq + 2);
    if (value_end == std::string::npos) break;
    out[tag.substr(name_start, eq - name_start)] = tag.substr(eq + 2, value_end - eq - 2);
    at = value_end + 1;
  }
  return out;
}

// The numbers of a points="x,y x,y ..." list.
std::vector<double> Numbers(const std::string& text) {
  std::vector<double> out;
  const char* c = text.c_str();
  while (*c != '\0') {
    char* stop = nullptr;
    const double v = std::strtod(c, &stop);
    if (stop == c) {
      ++c;
      continue;
    }
    out.push_back(v);
    c = stop;
  }
  return out;
}

// Points (x, y) of the driver's flipped frame as a path "Mx yl dx dy ..." of the page's frame,
// every point rounded to 0.1 px first; `close` appends "Z".
std::string PathOfPoints(const std::vector<double>& xy, double height, bool close) {
  std::string d;
  long px = 0, py = 0;
  for (size_t i = 0; i + 1 < xy.size(); i += 2) {
    AppendPathPoint(std::lround(10.0 * xy[i]), std::lround(10.0 * (height - xy[i + 1])), i == 0,
                    &px, &py, &d);
  }
  if (!d.empty() && d.back() == 'l') d += "0 0";  // one point: a dot (round caps)
  if (close && !d.empty()) d += "Z";
  return d;
}

std::string Number(const std::string& text) {
  return ShortNumber(std::strtod(text.c_str(), nullptr));
}

// &#xNN; character references as UTF-8 (markup characters stay references), so the text of
// the figure can be searched.
std::string DecodeCharacterReferences(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (text.compare(i, 3, "&#x") == 0) {
      const size_t end = text.find(';', i);
      if (end != std::string::npos) {
        const unsigned long code =
            std::strtoul(text.substr(i + 3, end - i - 3).c_str(), nullptr, 16);
        if (code == '<')
          out += "&lt;";
        else if (code == '&')
          out += "&amp;";
        else if (code == '>')
          out += "&gt;";
        else if (code < 0x80)
          out += static_cast<char>(code);
        else if (code < 0x800) {
          out += static_cast<char>(0xC0 | (code >> 6));
          out += static_cast<char>(0x80 | (code & 0x3F));
        } else if (code < 0x10000) {
          out += static_cast<char>(0xE0 | (code >> 12));
          out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
          out += static_cast<char>(0x80 | (code & 0x3F));
        } else {
          out += static_cast<char>(0xF0 | (code >> 18));
          out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
          out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
          out += static_cast<char>(0x80 | (code & 0x3F));
        }
        i = end + 1;
        continue;
      }
    }
    out += text[i++];
  }
  return out;
}

// The text's content: default font attributes dropped (the <svg> sets the family), the numbers
// of its <tspan> attributes shortened, references decoded. The words drawn keep every digit: a
// title "0.05018 ± 0.00066" or a tick "3.5221" shortened to one decimal read "0.1 ± 0" and "3.5"
// (issue 32).
std::string CompactTextContent(std::string content) {
  content = ReplaceAll(
      content, " font-family=\"sans-serif\" font-style=\"normal\" font-weight=\"normal\"", "");
  return DecodeCharacterReferences(SimplifyTagNumbers(content));
}

// One <text ...>content</text> of the flipped frame, in the page's frame.
std::string CompactText(const std::string& tag, const std::string& content, double height) {
  std::map<std::string, std::string> a = Attributes(tag);
  const std::vector<double> m = Numbers(a["transform"]);
  const double x = std::strtod(a["x"].c_str(), nullptr), y = std::strtod(a["y"].c_str(), nullptr);
  std::string out = "<text";
  if (m.size() == 6 && std::fabs(m[0] - 1.0) < 1e-9 && std::fabs(m[1]) < 1e-9 &&
      std::fabs(m[2]) < 1e-9 && std::fabs(m[3] + 1.0) < 1e-9) {
    out += " x=\"" + ShortNumber(m[4] + x) + "\" y=\"" + ShortNumber(height - m[5] + y) + "\"";
  } else if (m.size() == 6) {  // rotated: the flip composed with the text's own matrix
    out += " transform=\"matrix(" + ShortNumber(m[0]) + " " + ShortNumber(-m[1]) + " " +
           ShortNumber(m[2]) + " " + ShortNumber(-m[3]) + " " + ShortNumber(m[4]) + " " +
           ShortNumber(height - m[5]) + ")\" x=\"" + ShortNumber(x) + "\" y=\"" + ShortNumber(y) +
           "\"";
  }
  if (!a["font-size"].empty()) out += " font-size=\"" + Number(a["font-size"]) + "\"";
  if (!a["text-anchor"].empty() && a["text-anchor"] != "start")
    out += " text-anchor=\"" + a["text-anchor"] + "\"";
  if (!a["fill"].empty() && a["fill"] != "#000000") out += " fill=\"" + a["fill"] + "\"";
  if (!a["fill-opacity"].empty() && std::strtod(a["fill-opacity"].c_str(), nullptr) < 1.0)
    out += " fill-opacity=\"" + ShortNumber(std::strtod(a["fill-opacity"].c_str(), nullptr)) + "\"";
  return out + " xml:space=\"preserve\">" + CompactTextContent(content) + "</text>";
}

// The style of a <polyline> as attributes of the <path> it joins; "" for a fill's.
std::string StrokeStyle(std::map<std::string, std::string>& a) {
  std::string style = "fill=\"none\" stroke=\"" + a["stroke"] + "\" stroke-width=\"" +
                      Number(a["stroke-width"].empty() ? "1" : a["stroke-width"]) + "\"";
  const double opacity =
      a["stroke-opacity"].empty() ? 1.0 : std::strtod(a["stroke-opacity"].c_str(), nullptr);
  if (opacity < 1.0) style += " stroke-opacity=\"" + ShortNumber(opacity) + "\"";
  return style;
}

std::string FillStyle(std::map<std::string, std::string>& a) {
  std::string style = "fill=\"" + a["fill"] + "\"";
  const double opacity =
      a["fill-opacity"].empty() ? 1.0 : std::strtod(a["fill-opacity"].c_str(), nullptr);
  if (opacity < 1.0) style += " fill-opacity=\"" + ShortNumber(opacity) + "\"";
  if (!a["stroke"].empty() && a["stroke"] != "none")  // its outline too (no second fill=)
    style += " " + StrokeStyle(a).substr(std::string("fill=\"none\" ").size());
  return style;
}

// The whole page's clip of the driver's texts clips nothing.
bool WholePage(const std::vector<double>& xy, double width, double height) {
  double x_lo = HUGE_VAL, x_hi = -HUGE_VAL, y_lo = HUGE_VAL, y_hi = -HUGE_VAL;
  for (size_t i = 0; i + 1 < xy.size(); i += 2) {
    x_lo = std::min(x_lo, xy[i]), x_hi = std::max(x_hi, xy[i]);
    y_lo = std::min(y_lo, xy[i + 1]), y_hi = std::max(y_hi, xy[i + 1]);
  }
  return x_lo <= 0.5 && y_lo <= 0.5 && x_hi >= width - 0.5 && y_hi >= height - 0.5;
}

// PLplot's svg driver output rewritten: the flip applied, each run of polylines of one style as
// one <path> (a one-point polyline is a dot: round caps), texts as <text> with plain UTF-8
// content, clips of the whole page dropped, numbers at 0.1 px.
std::string CompactPlplotSvg(const std::string& svg) {
  const size_t svg_at = svg.find("<svg");
  const size_t svg_end = svg.find('>', svg_at);
  std::map<std::string, std::string> root = Attributes(svg.substr(svg_at, svg_end - svg_at));
  const std::vector<double> box = Numbers(root["viewBox"]);
  if (box.size() != 4) return svg;
  const double width = box[2], height = box[3];
  // The page in px, as PLplot was given it (the driver says pt: a third larger on screen).
  std::string out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"" +
      ShortNumber(width) + "\" height=\"" + ShortNumber(height) + "\" viewBox=\"" +
      root["viewBox"] +
      "\" font-family=\"sans-serif\" stroke-linecap=\"round\" stroke-linejoin=\"round\">\n";
  std::string run_style, run_d;
  auto flush = [&] {
    if (!run_d.empty()) out += "<path " + run_style + " d=\"" + run_d + "\"/>\n";
    run_d.clear();
    run_style.clear();
  };
  std::vector<bool> kept_groups;  // per open <g>: written (true) or dropped
  std::set<std::string> dropped_clips;
  size_t at = svg_end + 1;
  while (true) {
    const size_t start = svg.find('<', at);
    if (start == std::string::npos) break;
    const size_t end = svg.find('>', start);
    if (end == std::string::npos) break;
    const std::string tag = svg.substr(start, end + 1 - start);
    at = end + 1;
    if (tag.rfind("<polyline", 0) == 0) {
      std::map<std::string, std::string> a = Attributes(tag);
      const bool fill = !a["fill"].empty() && a["fill"] != "none";
      const std::string style = fill ? FillStyle(a) : StrokeStyle(a);
      if (style != run_style) flush();
      run_style = style;
      run_d += PathOfPoints(Numbers(a["points"]), height, fill);
    } else if (tag.rfind("<text", 0) == 0) {
      flush();
      const size_t close = svg.find("</text>", at);
      if (close == std::string::npos) break;
      out += CompactText(tag, svg.substr(at, close - at), height) + "\n";
      at = close + 7;
    } else if (tag.rfind("<rect", 0) == 0) {
      std::map<std::string, std::string> a = Attributes(tag);
      out += "<rect width=\"" + a["width"] + "\" height=\"" + a["height"] + "\" fill=\"" +
             a["fill"] + "\"/>\n";
    } else if (tag.rfind("<clipPath", 0) == 0) {
      flush();
      const std::string id = Attributes(tag)["id"];
      const size_t poly = svg.find("<polygon", at), close = svg.find("</clipPath>", at);
      if (poly == std::string::npos || close == std::string::npos) break;
      const std::vector<double> xy =
          Numbers(Attributes(svg.substr(poly, svg.find('>', poly) - poly))["points"]);
      if (WholePage(xy, width, height)) {
        dropped_clips.insert(id);
      } else {
        out += "<clipPath id=\"" + id + "\"><path d=\"" + PathOfPoints(xy, height, true) +
               "\"/></clipPath>\n";
      }
      at = close + 11;
    } else if (tag.rfind("<g", 0) == 0) {
      flush();
      std::map<std::string, std::string> a = Attributes(tag);
      const std::string clip = a["clip-path"];
      const std::string id = clip.size() > 6 ? clip.substr(5, clip.size() - 6) : "";
      const bool keep = !clip.empty() && dropped_clips.count(id) == 0;
      if (keep) out += "<g clip-path=\"" + clip + "\">\n";
      kept_groups.push_back(keep);
    } else if (tag == "</g>") {
      flush();
      if (!kept_groups.empty() && kept_groups.back()) out += "</g>\n";
      if (!kept_groups.empty()) kept_groups.pop_back();
    }
    // </svg>, comments: written below / dropped
  }
  flush();
  return out + "</svg>\n";
}

}  // namespace

std::string CompactSvg(const std::string& svg) {
  if (svg.find("<polyline") != std::string::npos ||
      svg.find("dominant-baseline") != std::string::npos)
    return CompactPlplotSvg(svg);
  return SimplifyTagNumbers(CompactSvgPaths(svg));
}

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
