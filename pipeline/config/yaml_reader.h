// Strict reading of YAML documents (configs, simulation specs) with yaml-cpp: every key that is
// read is marked, and Finish() rejects any key nobody asked for, with its dotted path and line.
// Internal to pipeline/ (includes yaml-cpp).
#pragma once

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "base/user_error.h"

namespace bifilar {

// A mapping node of a document: file name and dotted key path travel with it for messages.
class YamlMap {
 public:
  // Throws UserError when `node` is not a mapping (a null node counts as an empty mapping).
  YamlMap(const YAML::Node& node, std::string file, std::string path);

  // Loads `file` (throws UserError naming the file when it is missing, not a regular file,
  // larger than kMaxConfigBytes (base/bounded_read.h), not valid YAML, holds more than one
  // document, a repeated key or an alias ('*name': refused, see yaml_reader.cc)).
  static YamlMap LoadFile(const std::string& file);
  // The same checks on YAML text already in memory; `file` names it in messages.
  static YamlMap LoadText(const std::string& text, const std::string& file);

  bool Has(const std::string& key) const;
  // The value node; Required throws "file:line: missing required key 'a.b'".
  YAML::Node Required(const std::string& key);
  YAML::Node Optional(const std::string& key);  // undefined node when absent

  double RequiredDouble(const std::string& key);
  double OptionalDouble(const std::string& key, double fallback);
  int OptionalInt(const std::string& key, int fallback);
  // An integer in [lo, hi]; the message gives the range (also for values beyond 64 bits).
  long long OptionalIntIn(const std::string& key, long long fallback, long long lo, long long hi);
  bool OptionalBool(const std::string& key, bool fallback);
  std::string RequiredString(const std::string& key);
  std::string OptionalString(const std::string& key, const std::string& fallback);
  std::vector<double> OptionalDoubleList(const std::string& key, std::vector<double> fallback);
  std::vector<std::string> OptionalStringList(const std::string& key,
                                              std::vector<std::string> fallback);
  // A nested mapping (empty when absent).
  YamlMap Child(const std::string& key);

  // Throws UserError for the first key that was never read: "file:line: unknown key 'a.b'".
  void Finish() const;

  // "file:line:column" of a node of this document, for messages; "file" when unknown.
  std::string Where(const YAML::Node& node) const;
  std::string KeyPath(const std::string& key) const;
  // "file:line:column" of `key` itself in this mapping (of the mapping when absent).
  std::string WhereKey(const std::string& key) const;
  const std::string& file() const { return file_; }

  // Whether a value was given for `key`: false when the key is absent, true for a value, and a
  // UserError naming the key and line when it is present but blank (`key:`, `key: ~`, `null`):
  // a blank where `expected` ("a number", "true or false") is wanted is never read as a default
  // or as zero.
  bool Given(const YAML::Node& node, const std::string& key, const char* expected) const;

  // Scalar conversions that name the key and line on failure.
  double AsDouble(const YAML::Node& node, const std::string& key) const;
  std::string AsString(const YAML::Node& node, const std::string& key) const;

 private:
  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace bifilar
