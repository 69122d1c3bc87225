#include "pipeline/records/results_reader.h"

#include <cmath>

#include "base/user_error.h"

namespace bifilar {
namespace {

using nlohmann::json;

const json& Null() {
  static const json kNull(nullptr);
  return kNull;
}

void Collect(const json& j, const std::string& path, KeyLog* out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string child = path.empty() ? key : path + "." + key;
      out->insert(child);
      Collect(value, child, out);
    }
  } else if (j.is_array()) {
    for (const json& element : j) Collect(element, path + "[]", out);
  }
}

[[noreturn]] void Mistyped(const std::string& where, const char* expected, const json& v) {
  throw UserError(where + " is not " + expected + " (" + std::string(v.type_name()) + ")");
}

}  // namespace

ResultsReader::ResultsReader(const json& node, KeyLog* log, std::string path)
    : node_(&node), log_(log), path_(std::move(path)) {}

const json* ResultsReader::At(const char* key) const {
  if (log_ != nullptr) log_->insert(path_.empty() ? key : path_ + "." + key);
  if (!node_->is_object()) return nullptr;
  const auto it = node_->find(key);
  return it == node_->end() || it->is_null() ? nullptr : &*it;
}

bool ResultsReader::Has(const char* key) const { return At(key) != nullptr; }

std::string ResultsReader::Where(const char* key) const {
  return path_.empty() ? key : path_ + "." + key;
}

double ResultsReader::Num(const char* key) const {
  const json* v = At(key);
  if (v == nullptr) return NAN;
  if (!v->is_number()) Mistyped(Where(key), "a number", *v);
  return v->get<double>();
}

double ResultsReader::NumOrNull(const char* key, const std::string& file) const {
  const json* v = At(key);
  if (v == nullptr) return NAN;
  const std::string where = Where(key);
  if (!v->is_number()) {
    throw UserError(file + ": " + where + " is not a number (" + std::string(v->type_name()) + ")");
  }
  const double value = v->get<double>();
  if (!std::isfinite(value)) throw UserError(file + ": " + where + " is not finite");
  return value;
}

std::string ResultsReader::Str(const char* key) const {
  const json* v = At(key);
  if (v == nullptr) return "";
  if (!v->is_string()) Mistyped(Where(key), "text", *v);
  return v->get<std::string>();
}

bool ResultsReader::Bool(const char* key, bool fallback) const {
  const json* v = At(key);
  if (v == nullptr) return fallback;
  if (!v->is_boolean()) Mistyped(Where(key), "true or false", *v);
  return v->get<bool>();
}

int ResultsReader::Int(const char* key, int fallback) const {
  const json* v = At(key);
  if (v == nullptr) return fallback;
  if (!v->is_number_integer()) Mistyped(Where(key), "a whole number", *v);
  return v->get<int>();
}

ResultsReader ResultsReader::Get(const char* key) const {
  const json* v = At(key);
  return ResultsReader(v != nullptr ? *v : Null(), log_, path_.empty() ? key : path_ + "." + key);
}

std::vector<ResultsReader> ResultsReader::Items(const char* key) const {
  std::vector<ResultsReader> out;
  const json* v = At(key);
  if (v == nullptr) return out;
  if (!v->is_array()) Mistyped(Where(key), "a list", *v);
  const std::string path = Where(key) + "[]";
  for (const json& element : *v) out.emplace_back(element, log_, path);
  return out;
}

std::vector<double> ResultsReader::Nums(const char* key) const {
  std::vector<double> out;
  const json* v = At(key);
  if (v == nullptr) return out;
  if (!v->is_array()) Mistyped(Where(key), "a list", *v);
  for (const json& element : *v) {
    if (!element.is_number() && !element.is_null())
      Mistyped(Where(key) + "[]", "a number", element);
    out.push_back(element.is_number() ? element.get<double>() : NAN);
  }
  return out;
}

std::vector<std::string> ResultsReader::Strs(const char* key) const {
  std::vector<std::string> out;
  const json* v = At(key);
  if (v == nullptr) return out;
  if (!v->is_array()) Mistyped(Where(key), "a list", *v);
  for (const json& element : *v) {
    if (!element.is_string()) Mistyped(Where(key) + "[]", "text", element);
    out.push_back(element.get<std::string>());
  }
  return out;
}

std::vector<std::vector<double>> ResultsReader::Rows(const char* key) const {
  std::vector<std::vector<double>> out;
  const json* v = At(key);
  if (v == nullptr) return out;
  if (!v->is_array()) Mistyped(Where(key), "a list", *v);
  for (const json& row : *v) {
    std::vector<double> values;
    if (row.is_array()) {
      for (const json& x : row) {
        if (!x.is_number() && !x.is_null()) Mistyped(Where(key) + "[][]", "a number", x);
        values.push_back(x.is_number() ? x.get<double>() : NAN);
      }
    } else if (!row.is_null()) {
      Mistyped(Where(key) + "[]", "a list", row);
    }
    out.push_back(values);
  }
  return out;
}

KeyLog KeyPaths(const json& document) {
  KeyLog out;
  Collect(document, "", &out);
  return out;
}

}  // namespace bifilar
