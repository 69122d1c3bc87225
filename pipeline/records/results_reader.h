// The one reader of results.json (the document ResultsToJson writes, pipeline/records/
// results_json.h, with its ellipse_json.h and tensor_json.h sections), shared by the report and
// export. A ResultsReader is a typed view of one node: a missing key or null reads as NaN / "" /
// the fallback (a results file of an older version still gives a page); a value of another type
// throws UserError naming its key path ("traces[].window_s[] is not a number (string)"). Every
// key read can be logged (`KeyLog`), and tests/pipeline_report_kinds_test.cc checks that each key
// the report and export read is one the writer writes for some kind of campaign: reading a key
// the writer never writes is caught there.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace bifilar {

// Key paths read, "traces[].inertia_kg_m2" (array elements as []).
using KeyLog = std::set<std::string>;

class ResultsReader {
 public:
  // `node` must outlive the reader and every reader taken from it.
  explicit ResultsReader(const nlohmann::json& node, KeyLog* log = nullptr, std::string path = "");

  bool IsObject() const { return node_->is_object(); }
  bool Has(const char* key) const;    // present and not null
  double Num(const char* key) const;  // NaN unless a number
  // A number or null/missing (NaN); anything else, or a non-finite number, throws UserError
  // "`file`: PATH.KEY is not a number (TYPE)" (export, which must not write a wrong file).
  double NumOrNull(const char* key, const std::string& file) const;
  std::string Str(const char* key) const;  // "" unless text
  bool Bool(const char* key, bool fallback = false) const;
  int Int(const char* key, int fallback = 0) const;
  ResultsReader Get(const char* key) const;                 // a child (null when missing)
  std::vector<ResultsReader> Items(const char* key) const;  // an array's elements
  std::vector<double> Nums(const char* key) const;          // NaN for non-numbers
  std::vector<std::string> Strs(const char* key) const;     // text elements only
  // An array of arrays of numbers (rows of NaN for non-arrays).
  std::vector<std::vector<double>> Rows(const char* key) const;
  const std::string& path() const { return path_; }
  // The node itself, for the typed reader of a section (TraceRecordFromJson for traces[]).
  const nlohmann::json& node() const { return *node_; }

 private:
  const nlohmann::json* At(const char* key) const;
  std::string Where(const char* key) const;
  const nlohmann::json* node_;
  KeyLog* log_;
  std::string path_;
};

// Every key path of `document` (objects' keys, arrays as []), for comparing with a KeyLog.
KeyLog KeyPaths(const nlohmann::json& document);

}  // namespace bifilar
