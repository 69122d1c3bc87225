#include "pipeline/yaml_reader.h"

#include <cmath>

namespace bifilar {
namespace {

// An absent key comes back from yaml-cpp as an invalid "zombie" node whose type queries (and
// assignment) throw: treat it as an empty document.
YAML::Node ValidOrNull(const YAML::Node& node) {
  return node.IsDefined() ? node : YAML::Node(YAML::NodeType::Null);
}

}  // namespace

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string path)
    : node_(ValidOrNull(node)), file_(std::move(file)), path_(std::move(path)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    throw UserError(Where(node_) + ": '" + (path_.empty() ? "<document>" : path_) +
                    "' must be a mapping of keys to values");
  }
}

YamlMap YamlMap::LoadFile(const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw UserError(file + ": cannot open file");
  } catch (const YAML::Exception& e) {
    throw UserError(file + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
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

bool YamlMap::Has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined();
}

YAML::Node YamlMap::Optional(const std::string& key) {
  used_.insert(key);
  if (!node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& const_node = node_;
  return const_node[key];
}

YAML::Node YamlMap::Required(const std::string& key) {
  YAML::Node value = Optional(key);
  if (!value.IsDefined() || value.IsNull()) {
    throw UserError(Where(node_) + ": missing required key '" + KeyPath(key) + "'");
  }
  return value;
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
  return value.IsDefined() && !value.IsNull() ? AsDouble(value, key) : fallback;
}

int YamlMap::OptionalInt(const std::string& key, int fallback) {
  YAML::Node value = Optional(key);
  if (!value.IsDefined() || value.IsNull()) return fallback;
  int result = 0;
  if (!value.IsScalar() || !YAML::convert<int>::decode(value, result)) {
    throw UserError(Where(value) + ": '" + KeyPath(key) + "' must be an integer");
  }
  return result;
}

bool YamlMap::OptionalBool(const std::string& key, bool fallback) {
  YAML::Node value = Optional(key);
  if (!value.IsDefined() || value.IsNull()) return fallback;
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
  if (!value.IsDefined() || value.IsNull()) return fallback;
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

YamlMap YamlMap::Child(const std::string& key) { return YamlMap(Optional(key), file_, KeyPath(key)); }

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
