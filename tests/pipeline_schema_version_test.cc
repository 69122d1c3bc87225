// The schema version of results.json and of a cache entry (kResultsSchemaVersion, base/version.h;
// issue 36 item 4): both writers write it; `report` and `export` refuse a results.json of a newer
// schema naming the file and both numbers, and read an older one (no number: 0.3.0 and earlier)
// as before; the cache refits an entry of an older schema and refuses one of a newer.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "base/version.h"
#include "pipeline/records/results_json.h"
#include "pipeline/report/export.h"
#include "pipeline/report/report.h"
#include "pipeline/store/cache.h"
#include "test_support.h"

namespace bifilar {
namespace {

using nlohmann::json;
using test_support::ErrorOf;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

const std::string kNewer = std::to_string(kResultsSchemaVersion + 1);
const std::string kCurrent = std::to_string(kResultsSchemaVersion);

TEST(SchemaVersion, ResultsJsonAndCacheEntriesCarryIt) {
  EXPECT_GE(kResultsSchemaVersion, 1);
  const json results = ResultsToJson(CampaignConfig(), CampaignResult());
  EXPECT_EQ(results.at("schema_version"), kResultsSchemaVersion);
  EXPECT_EQ(SchemaVersionOf(results), kResultsSchemaVersion);
  EXPECT_EQ(SchemaVersionOf(json{{"version", "0.3.0"}}), 0);  // written before the number
  EXPECT_NE(ErrorOf([] {
              SchemaVersionOf(json{{"schema_version", "1"}});
            }).find("'schema_version' is not a whole number >= 0 (\"1\")"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { SchemaVersionOf(json{{"schema_version", -1}}); }), "");
  EXPECT_NE(ErrorOf([] { SchemaVersionOf(json{{"schema_version", 1.5}}); }), "");

  TempDir dir("bifilar_schema");
  const TraceCache cache(dir.path + "/cache");
  cache.Store("00000000000000k1", "00000000000000aa", TraceRecord());
  EXPECT_EQ(json::parse(ReadFile(cache.EntryPath("00000000000000k1"))).at("schema_version"),
            kResultsSchemaVersion);
}

// `bifilar report` on a results.json of a newer schema: one error naming the file, its schema
// and writer, this bifilar's schema, and what to do; the page is not written.
TEST(SchemaVersion, ReportRefusesANewerResultsJson) {
  TempDir dir("bifilar_schema");
  json results = {{"program", "bifilar"}, {"version", "9.1.0"}, {"traces", json::array()}};
  results["schema_version"] = kResultsSchemaVersion + 1;
  const std::string path = WriteFile(dir.path + "/results.json", results.dump(1));
  const std::string error = ErrorOf([&] { RunReport(dir.path); });
  for (const std::string& part :
       {path + ": results schema " + kNewer + ", written by bifilar 9.1.0",
        "this is bifilar " + std::string(ProgramVersion()) + ", which reads schema " + kCurrent +
            " and older",
        std::string("rerun `bifilar process` with this one")}) {
    EXPECT_NE(error.find(part), std::string::npos) << part << " not in: " << error;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path + "/report.html"));
  results["schema_version"] = "two";
  WriteFile(path, results.dump(1));
  EXPECT_NE(ErrorOf([&] {
              RunReport(dir.path);
            }).find(path + ": 'schema_version' is not a whole number >= 0 (\"two\")"),
            std::string::npos);
}

// `bifilar export` reads a results.json of its own schema and an older one (no number), and
// refuses a newer one with the file's name and both numbers.
TEST(SchemaVersion, ExportRefusesANewerResultsJson) {
  json tensor;
  for (const char* name : {"Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"}) {
    tensor[std::string(name) + "_kg_m2"] = 1.0;
    tensor[std::string(name) + "_kg_m2_std"] = 0.01;
  }
  json results = {{"program", "bifilar"}, {"version", "9.1.0"}, {"config", ""}, {"tensor", tensor}};
  ExportOptions options;
  options.results_path = "in/results.json";
  options.mass_kg = 1.0;
  const auto read = [&] {
    return ErrorOf([&] { ReadExportInertia(results.dump(), "in/results.json", options); });
  };
  EXPECT_EQ(read(), "");  // no number: schema 0, older, read as before
  results["schema_version"] = kResultsSchemaVersion;
  EXPECT_EQ(read(), "");
  results["schema_version"] = kResultsSchemaVersion + 1;
  EXPECT_NE(read().find("in/results.json: results schema " + kNewer +
                        ", written by bifilar 9.1.0; this is bifilar " + ProgramVersion() +
                        ", which reads schema " + kCurrent + " and older"),
            std::string::npos)
      << read();
}

// A cache entry of an older schema is a miss (refitted and overwritten, no warning); one of a
// newer schema or a schema that is not a number is refused, saying why.
TEST(SchemaVersion, CacheRefitsAnOlderEntryAndRefusesANewerOne) {
  TempDir dir("bifilar_schema");
  const TraceCache cache(dir.path + "/cache");
  TraceRecord r;
  r.file = "pitch_0/trial_1.csv";
  r.status = TraceStatus::kOk;
  r.inertia_total_kg_m2 = 4.1;
  r.inertia_total_std_kg_m2 = 2e-5;
  const std::string key = "00000000000000k1", hash = "00000000000000aa";
  cache.Store(key, hash, r);
  const json good = json::parse(ReadFile(cache.EntryPath(key)));
  const auto load = [&](const json& entry) {
    WriteFile(cache.EntryPath(key), entry.dump(1));
    TraceRecord loaded;
    std::string problem;
    const bool hit = cache.Load(key, hash, &loaded, &problem);
    return hit ? std::string("hit") : problem.empty() ? std::string("miss") : problem;
  };
  EXPECT_EQ(load(good), "hit");
  json old = good;
  old.erase("schema_version");  // as written before the number existed
  EXPECT_EQ(load(old), "miss");
  old["schema_version"] = kResultsSchemaVersion - 1;
  EXPECT_EQ(load(old), "miss");
  json newer = good;
  newer["schema_version"] = kResultsSchemaVersion + 1;
  EXPECT_EQ(load(newer), cache.EntryPath(key) + ": cache entry refused (schema " + kNewer +
                             ", newer than this bifilar's " + kCurrent + ")");
  newer["schema_version"] = "1";
  EXPECT_NE(load(newer).find("'schema_version' is not a whole number"), std::string::npos);
}

}  // namespace
}  // namespace bifilar
