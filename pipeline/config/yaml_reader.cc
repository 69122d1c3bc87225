#include "pipeline/config/yaml_reader.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include <yaml-cpp/anchor.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include "base/bounded_read.h"

namespace bifilar {
namespace {

// An absent key comes back from yaml-cpp as an invalid "zombie" node whose type queries (and
// assignment) throw: treat it as an empty document.
YAML::Node ValidOrNull(const YAML::Node& node) {
  return node.IsDefined() ? node : YAML::Node(YAML::NodeType::Null);
}

// Line (1-based) of a node, 0 when unknown.
int Line(const YAML::Node& node) { return node.Mark().is_null() ? 0 : node.Mark().line + 1; }

// yaml-cpp keeps both entries of a repeated key and answers lookups with the first: a repeated
// key anywhere in the tree is an error naming both lines.
void RejectDuplicateKeys(const YAML::Node& node, const std::string& file, const std::string& path) {
  if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) {
      RejectDuplicateKeys(node[i], file, path + "[" + std::to_string(i) + "]");
    }
    return;
  }
  if (!node.IsMap()) return;
  std::map<std::string, int> first_line;
  for (const auto& item : node) {
    const std::string key = item.first.IsScalar() ? item.first.Scalar() : std::string();
    const std::string key_path = path.empty() ? key : path + "." + key;
    if (item.first.IsScalar()) {
      auto [it, inserted] = first_line.emplace(key, Line(item.first));
      if (!inserted) {
        throw UserError(file + ":" + std::to_string(Line(item.first)) + ": duplicate key '" +
                        key_path + "' (first at line " + std::to_string(it->second) +
                        "); give each key once");
      }
    }
    RejectDuplicateKeys(item.second, file, key_path);
  }
}

// Refuses YAML aliases (`*name`, and the merge key `<< : *name` built on them) before the
// document is built: yaml-cpp shares an aliased node, so a 1 kB "billion laughs" document
// (aliases of aliases) is a tree of 9^10 nodes to any code that walks it. A config spells its
// values out; an alias is an error naming its line.
class AliasRefuser : public YAML::EventHandler {
 public:
  AliasRefuser(const std::string& text, const std::string& file) : text_(text), file_(file) {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    // The alias as written ("*base"), from its position in the text.
    std::string alias = "*name";
    if (mark.pos >= 0 && static_cast<size_t>(mark.pos) < text_.size() && text_[mark.pos] == '*') {
      const size_t end = text_.find_first_of(" \t\r\n,]}", mark.pos);
      alias = text_.substr(mark.pos, std::min<size_t>(end, mark.pos + 40) - mark.pos);
    }
    throw UserError(file_ + ":" + std::to_string(mark.line + 1) + ":" +
                    std::to_string(mark.column + 1) + ": YAML alias '" + alias +
                    "'; bifilar reads no aliases or merge keys ('<<') in its YAML files: write "
                    "the values out where they are used");
  }
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

 private:
  const std::string& text_;
  const std::string& file_;
};

}  // namespace

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string path)
    : node_(ValidOrNull(node)), file_(std::move(file)), path_(std::move(path)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    throw UserError(Where(node_) + ": '" + (path_.empty() ? "<document>" : path_) +
                    "' must be a mapping of keys to values");
  }
}

YamlMap YamlMap::LoadFile(const std::string& file) {
  return LoadText(ReadRegularFileOrThrow(file, ConfigCap()), file);
}

YamlMap YamlMap::LoadText(const std::string& text, const std::string& file) {
  std::vector<YAML::Node> documents;
  try {
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    AliasRefuser refuser(text, file);
    while (parser.HandleNextDocument(refuser)) {
    }
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    throw UserError(file + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  if (documents.size() > 1) {
    throw UserError(file + ":" + std::to_string(Line(documents[1])) +
                    ": a second YAML document (the first starts at line " +
                    std::to_string(std::max(1, Line(documents[0]))) +
                    "); a config is one document: remove the '---' and merge the keys");
  }
  const YAML::Node root = documents.empty() ? YAML::Node(YAML::NodeType::Null) : documents[0];
  RejectDuplicateKeys(root, file, "");
  return YamlMap(root, file, "");
}

std::string YamlMap::Where(const YAML::Node& node) const {
  if (!node.IsDefined() || node.Mark().is_null()) return file_;
  return file_ + ":" + std::to_string(node.Mark().line + 1) + ":" +
         std::to_string(node.Mark().column + 1);
}

std::string YamlMap::KeyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

bool YamlMap::Has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined(); }

YAML::Node YamlMap::Optional(const std::string& key) {
  used_.insert(key);
  if (!node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& const_node = node_;
  return const_node[key];
}

YAML::Node YamlMap::Required(const std::string& key) {
  YAML::Node value = Optional(key);
  if (!value.IsDefined()) {
    throw UserError(Where(node_) + ": missing required key '" + KeyPath(key) + "'");
  }
  if (value.IsNull()) {
    throw UserError(WhereKey(key) + ": '" + KeyPath(key) +
                    "' is blank (or ~ / null): give its value; a blank is not read as 0");
  }
  return value;
}

std::string YamlMap::WhereKey(const std::string& key) const {
  // A blank value's mark is the next token (often the next line): name the key's own place.
  if (node_.IsMap()) {
    for (const auto& item : node_) {
      if (item.first.IsScalar() && item.first.Scalar() == key) return Where(item.first);
    }
  }
  return Where(node_);
}

bool YamlMap::Given(const YAML::Node& node, const std::string& key, const char* expected) const {
  if (!node.IsDefined()) return false;
  if (node.IsNull()) {
    throw UserError(WhereKey(key) + ": '" + KeyPath(key) + "' is blank (or ~ / null): give " +
                    expected + ", or remove the key to use its default");
  }
  return true;
}

double YamlMap::AsDouble(const YAML::Node& node, const std::string& key) const {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    throw UserError(Where(node) + ": '" + KeyPath(key) + "' must be a finite number");
  }
  return value;
}

std::string YamlMap::AsString(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) {
    throw UserError(Where(node) + ": '" + KeyPath(key) + "' must be a single value");
  }
  return node.Scalar();
}

double YamlMap::RequiredDouble(const std::string& key) { return AsDouble(Required(key), key); }

double YamlMap::OptionalDouble(const std::string& key, double fallback) {
  YAML::Node value = Optional(key);
  return Given(value, key, "a number") ? AsDouble(value, key) : fallback;
}

int YamlMap::OptionalInt(const std::string& key, int fallback) {
  return static_cast<int>(OptionalIntIn(key, fallback, std::numeric_limits<int>::min(),
                                        std::numeric_limits<int>::max()));
}

long long YamlMap::OptionalIntIn(const std::string& key, long long fallback, long long lo,
                                 long long hi) {
  YAML::Node value = Optional(key);
  if (!Given(value, key, "an integer")) return fallback;
  long long result = 0;
  if (!value.IsScalar() || !YAML::convert<long long>::decode(value, result) || result < lo ||
      result > hi) {
    const std::string got = value.IsScalar() ? value.Scalar() : std::string("a list or mapping");
    throw UserError(Where(value) + ": '" + KeyPath(key) + "' must be an integer in [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "], got '" +
                    got.substr(0, 40) + (got.size() > 40 ? "...'" : "'"));
  }
  return result;
}

bool YamlMap::OptionalBool(const std::string& key, bool fallback) {
  YAML::Node value = Optional(key);
  if (!Given(value, key, "true or false")) return fallback;
  bool result = false;
  if (!value.IsScalar() || !YAML::convert<bool>::decode(value, result)) {
    throw UserError(Where(value) + ": '" + KeyPath(key) + "' must be true or false");
  }
  return result;
}

std::string YamlMap::RequiredString(const std::string& key) { return AsString(Required(key), key); }

std::string YamlMap::OptionalString(const std::string& key, const std::string& fallback) {
  YAML::Node value = Optional(key);
  return value.IsDefined() && !value.IsNull() ? AsString(value, key) : fallback;
}

std::vector<double> YamlMap::OptionalDoubleList(const std::string& key,
                                                std::vector<double> fallback) {
  YAML::Node value = Optional(key);
  if (!Given(value, key, "a list of numbers")) return fallback;
  if (!value.IsSequence()) {
    throw UserError(Where(value) + ": '" + KeyPath(key) + "' must be a list of numbers");
  }
  std::vector<double> result;
  for (const auto& item : value) result.push_back(AsDouble(item, key));
  return result;
}

std::vector<std::string> YamlMap::OptionalStringList(const std::string& key,
                                                     std::vector<std::string> fallback) {
  YAML::Node value = Optional(key);
  if (!value.IsDefined() || value.IsNull()) return fallback;
  if (!value.IsSequence()) {
    throw UserError(Where(value) + ": '" + KeyPath(key) + "' must be a list");
  }
  std::vector<std::string> result;
  for (const auto& item : value) result.push_back(AsString(item, key));
  return result;
}

YamlMap YamlMap::Child(const std::string& key) {
  return YamlMap(Optional(key), file_, KeyPath(key));
}

void YamlMap::Finish() const {
  if (!node_.IsMap()) return;
  for (const auto& item : node_) {
    const std::string key = item.first.Scalar();
    if (used_.count(key) == 0) {
      throw UserError(Where(item.first) + ": unknown key '" + KeyPath(key) + "'");
    }
  }
}

}  // namespace bifilar
