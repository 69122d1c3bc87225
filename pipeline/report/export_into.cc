// `bifilar export --into MODEL --link NAME` (pipeline/report/export.h): the inertial block of one
// link (URDF, SDF) or body (MJCF) of a model file replaced by text, every other byte as it was.
// The model is scanned, not parsed into a tree and written back: a tree would re-indent, reorder
// attributes and drop comments. The scanner knows elements, attributes in quotes, comments,
// CDATA, processing instructions and <!DOCTYPE>, which is all the XML of these formats holds.
#include <algorithm>
#include <cctype>
#include <sstream>
#include <string>
#include <vector>

#include "base/user_error.h"
#include "pipeline/report/export.h"
#include "pipeline/report/export_steps.h"

namespace bifilar {
namespace {

// One element of the scanned document: byte offsets into the text.
struct XmlElement {
  std::string name;
  size_t begin = 0;       // its '<'
  size_t open_end = 0;    // just after the '>' of its start tag
  size_t end = 0;         // just after its end tag (== open_end when self-closing)
  int parent = -1;        // index in the element list; -1 for the root
  std::string start_tag;  // the start tag's text, "<name a="1">"
};

struct XmlScan {
  std::vector<XmlElement> elements;
  std::vector<std::pair<size_t, size_t>> comments;  // [begin, end) of every <!-- -->
};

// Scans `text`; throws UserError naming `name` and the byte offset on what is not well-formed.
XmlScan ScanXml(const std::string& text, const std::string& name) {
  XmlScan scan;
  std::vector<int> open;  // indices of the elements not yet closed
  const auto fail = [&](size_t at, const std::string& what) {
    throw UserError("export --into: " + name + ": not well-formed XML at byte " +
                    std::to_string(at) + ": " + what);
  };
  size_t i = 0;
  while ((i = text.find('<', i)) != std::string::npos) {
    const auto skip_to = [&](const char* close, const char* what) {
      const size_t e = text.find(close, i);
      if (e == std::string::npos) fail(i, std::string("unclosed ") + what);
      return e + std::string(close).size();
    };
    if (text.compare(i, 4, "<!--") == 0) {
      const size_t e = skip_to("-->", "comment");
      scan.comments.emplace_back(i, e);
      i = e;
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      i = skip_to("]]>", "CDATA section");
    } else if (text.compare(i, 2, "<?") == 0) {
      i = skip_to("?>", "processing instruction");
    } else if (text.compare(i, 2, "<!") == 0) {
      i = skip_to(">", "declaration");
    } else {
      // A tag: the name, then attributes whose quoted values may hold '>'.
      size_t j = i + 1;
      const bool closing = j < text.size() && text[j] == '/';
      if (closing) ++j;
      const size_t name_begin = j;
      while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j])) &&
             text[j] != '>' && text[j] != '/') {
        ++j;
      }
      const std::string tag = text.substr(name_begin, j - name_begin);
      if (tag.empty()) fail(i, "a '<' without an element name");
      char quote = 0;
      for (; j < text.size(); ++j) {
        if (quote) {
          if (text[j] == quote) quote = 0;
        } else if (text[j] == '"' || text[j] == '\'') {
          quote = text[j];
        } else if (text[j] == '>') {
          break;
        }
      }
      if (j >= text.size()) fail(i, "unclosed tag <" + tag);
      const size_t after = j + 1;
      if (closing) {
        if (open.empty() || scan.elements[open.back()].name != tag) {
          fail(i, "</" + tag + "> does not close the open element");
        }
        scan.elements[open.back()].end = after;
        open.pop_back();
      } else {
        XmlElement e;
        e.name = tag;
        e.begin = i;
        e.open_end = after;
        e.end = after;
        e.parent = open.empty() ? -1 : open.back();
        e.start_tag = text.substr(i, after - i);
        scan.elements.push_back(e);
        if (text[j - 1] != '/') open.push_back(static_cast<int>(scan.elements.size()) - 1);
      }
      i = after;
    }
  }
  if (!open.empty()) fail(text.size(), "<" + scan.elements[open.back()].name + "> is not closed");
  if (scan.elements.empty()) fail(0, "no element");
  return scan;
}

// The value of attribute `key` in a start tag ("" and false when absent).
bool Attribute(const std::string& start_tag, const std::string& key, std::string* value) {
  size_t at = 0;
  while ((at = start_tag.find(key, at)) != std::string::npos) {
    const bool starts = at > 0 && std::isspace(static_cast<unsigned char>(start_tag[at - 1]));
    size_t j = at + key.size();
    while (j < start_tag.size() && std::isspace(static_cast<unsigned char>(start_tag[j]))) ++j;
    if (starts && j < start_tag.size() && start_tag[j] == '=') {
      ++j;
      while (j < start_tag.size() && std::isspace(static_cast<unsigned char>(start_tag[j]))) ++j;
      if (j < start_tag.size() && (start_tag[j] == '"' || start_tag[j] == '\'')) {
        const size_t close = start_tag.find(start_tag[j], j + 1);
        if (close == std::string::npos) return false;
        *value = start_tag.substr(j + 1, close - j - 1);
        return true;
      }
    }
    at += key.size();
  }
  value->clear();
  return false;
}

// Up to `n` numbers of a space-separated text; false when one is not a number.
bool Numbers(const std::string& text, size_t n, std::vector<double>* out) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  out->clear();
  double v = 0;
  while (out->size() < n && in >> v) out->push_back(v);
  return out->size() == n;
}

// The element of `scan` that is a direct child of `parent` named `tag` (-1: none).
int Child(const XmlScan& scan, int parent, const std::string& tag) {
  for (size_t k = 0; k < scan.elements.size(); ++k) {
    if (scan.elements[k].parent == parent && scan.elements[k].name == tag)
      return static_cast<int>(k);
  }
  return -1;
}

// The inertial origin the model's block holds (its position kept; a rotation dropped with a
// warning: the tensor is written in the link's axes).
InertialOrigin KeptOrigin(const std::string& text, const XmlScan& scan, int inertial,
                          ExportFormat format, const std::string& where,
                          std::vector<std::string>* warnings) {
  InertialOrigin o;
  o.note = "the inertial position is the model's own, kept as it was (no aircraft.cg_m given).";
  if (inertial < 0) {
    o.note =
        "the inertial position is the link origin, 0 0 0 (the model had no inertial and no "
        "aircraft.cg_m was given).";
    return o;
  }
  std::vector<double> v;
  bool rotated = false;
  std::string value;
  if (format == ExportFormat::kMjcf) {
    const std::string& tag = scan.elements[inertial].start_tag;
    if (Attribute(tag, "pos", &value) && Numbers(value, 3, &v)) o.xyz = {v[0], v[1], v[2]};
    for (const char* r : {"quat", "axisangle", "xyaxes", "zaxis", "euler"}) {
      rotated = rotated || Attribute(tag, r, &value);
    }
  } else if (format == ExportFormat::kUrdf) {
    const int origin = Child(scan, inertial, "origin");
    if (origin >= 0) {
      const std::string& tag = scan.elements[origin].start_tag;
      if (Attribute(tag, "xyz", &value) && Numbers(value, 3, &v)) o.xyz = {v[0], v[1], v[2]};
      rotated = Attribute(tag, "rpy", &value) && Numbers(value, 3, &v) &&
                (v[0] != 0 || v[1] != 0 || v[2] != 0);
    }
  } else {
    const int pose = Child(scan, inertial, "pose");
    if (pose >= 0) {
      const XmlElement& e = scan.elements[pose];
      const size_t close = text.rfind('<', e.end - 1);
      const std::string inner =
          close > e.open_end ? text.substr(e.open_end, close - e.open_end) : "";
      if (Numbers(inner, 6, &v)) {
        o.xyz = {v[0], v[1], v[2]};
        rotated = v[3] != 0 || v[4] != 0 || v[5] != 0;
      } else if (Numbers(inner, 3, &v)) {
        o.xyz = {v[0], v[1], v[2]};
      }
      if (Attribute(e.start_tag, "relative_to", &value)) {
        warnings->push_back(where + ": the inertial <pose relative_to=\"" + value +
                            "\"> is written without it: the position is kept, in the link frame");
      }
    }
  }
  if (rotated) {
    warnings->push_back(where +
                        ": the model's inertial frame was rotated; the measured tensor "
                        "is written in the link's own axes, so the rotation is dropped");
  }
  return o;
}

// `block` (lines ending in "\n") re-indented for a place whose line starts with `indent`: no
// indent on its first line (the text before it keeps its own) and no final line break.
std::string Indented(const std::string& block, const std::string& indent) {
  std::string out;
  for (size_t i = 0; i + 1 < block.size(); ++i) {
    out += block[i];
    if (block[i] == '\n') out += indent;
  }
  return out;
}

// The whitespace that starts the line of offset `at` (up to `at`); "" when other text precedes.
std::string LineIndent(const std::string& text, size_t at) {
  size_t b = at;
  while (b > 0 && (text[b - 1] == ' ' || text[b - 1] == '\t')) --b;
  if (b > 0 && text[b - 1] != '\n') return "";
  return text.substr(b, at - b);
}

}  // namespace

bool DetectModelFormat(const std::string& model, ExportFormat* format) {
  XmlScan scan;
  try {
    scan = ScanXml(model, "model");
  } catch (const UserError&) {
    return false;
  }
  const std::string& root = scan.elements[0].name;
  if (root == "robot")
    *format = ExportFormat::kUrdf;
  else if (root == "sdf")
    *format = ExportFormat::kSdf;
  else if (root == "mujoco")
    *format = ExportFormat::kMjcf;
  else
    return false;
  return true;
}

std::string RewriteModelInertial(const std::string& model, const std::string& model_name,
                                 const std::string& link, const ExportInertia& inertia,
                                 ExportFrame frame, bool force,
                                 std::vector<std::string>* warnings) {
  const XmlScan scan = ScanXml(model, model_name);
  ExportFormat format;
  if (!DetectModelFormat(model, &format)) {
    throw UserError("export --into: " + model_name +
                    " is not a URDF (<robot>), SDF (<sdf>) or MJCF (<mujoco>) model");
  }
  const std::string tag = format == ExportFormat::kMjcf ? "body" : "link";
  std::vector<int> found;
  std::string names;
  for (size_t k = 0; k < scan.elements.size(); ++k) {
    if (scan.elements[k].name != tag) continue;
    std::string n;
    Attribute(scan.elements[k].start_tag, "name", &n);
    names += (names.empty() ? "" : ", ") + n;
    if (n == link) found.push_back(static_cast<int>(k));
  }
  const std::string where = model_name + ": " + tag + " '" + link + "'";
  if (found.empty()) {
    throw UserError("export --into: " + model_name + " has no " + tag + " named '" + link + "' (" +
                    (names.empty() ? "it has none" : "its " + tag + "s: " + names) + ")");
  }
  if (found.size() > 1) {
    throw UserError("export --into: " + model_name + " has " + std::to_string(found.size()) + " " +
                    tag + "s named '" + link + "'; which one is meant is not clear");
  }
  const XmlElement& owner = scan.elements[found[0]];
  if (owner.end == owner.open_end) {
    throw UserError("export --into: " + where + " is an empty element (<" + tag +
                    " .../>); write it as <" + tag + " ...></" + tag + "> first");
  }
  const int inertial = Child(scan, found[0], "inertial");
  // The span replaced: the <inertial> element, with export's comment just before it (only
  // whitespace between): so a second export replaces the first one's comment too.
  size_t begin = 0, end = 0;
  bool ours = false;
  if (inertial >= 0) {
    begin = scan.elements[inertial].begin;
    end = scan.elements[inertial].end;
    for (const auto& [cb, ce] : scan.comments) {
      if (ce > begin || cb < owner.open_end) continue;
      if (model.compare(cb, std::string(kExportMark).size(), kExportMark) != 0) continue;
      if (model.find_first_not_of(" \t\r\n", ce) == begin) {
        begin = cb;
        ours = true;
      }
    }
  }
  if (!ours && !force) {
    throw UserError(
        "export --into: " + where +
        (inertial >= 0 ? "'s <inertial> was not written by bifilar export" : " has no <inertial>") +
        "; add --force to replace it (the file as it was is kept as a backup)");
  }
  if (format == ExportFormat::kMjcf) {
    for (const XmlElement& e : scan.elements) {
      std::string v;
      if (e.name == "compiler" && Attribute(e.start_tag, "inertiafromgeom", &v) && v == "true") {
        warnings->push_back(model_name +
                            ": <compiler inertiafromgeom=\"true\"> makes MuJoCo "
                            "compute every body's inertia from its geoms and ignore <inertial>");
      }
    }
  }
  const InertialOrigin origin = inertia.cg.Given()
                                    ? DefaultOrigin(inertia, format, frame)
                                    : KeptOrigin(model, scan, inertial, format, where, warnings);
  const std::string block = InertialBlock(inertia, format, frame, origin);
  if (inertial >= 0) {
    return model.substr(0, begin) + Indented(block, LineIndent(model, begin)) + model.substr(end);
  }
  // No <inertial>: a new first child, on its own line, indented one step below the link.
  const std::string indent = LineIndent(model, owner.begin) + "  ";
  return model.substr(0, owner.open_end) + "\n" + indent + Indented(block, indent) +
         model.substr(owner.open_end);
}

}  // namespace bifilar
