// Cache: the FNV-1a hash against published test vectors, which config values enter a trace's
// key (and which do not), entries surviving a store/load round trip, and entries refused.
#include "pipeline/store/cache.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/version.h"
#include "test_support.h"

namespace bifilar {
namespace {

// An ok record with the few fields the cache tests look at.
TraceRecord OkRecord() {
  TraceRecord r;
  r.file = "pitch_0/trial_1.csv";
  r.status = TraceStatus::kOk;
  r.inertia_total_kg_m2 = 4.1;
  r.inertia_total_std_kg_m2 = 2e-5;
  r.model = "full";
  return r;
}

TEST(Cache, Fnv1a64MatchesReferenceVectors) {
  // Vectors from the FNV reference (isthe.com/chongo/tech/comp/fnv, test_fnv.c, FNV-1a 64).
  EXPECT_EQ(Fnv1a64(std::string("")), 0xcbf29ce484222325ULL);
  EXPECT_EQ(Fnv1a64(std::string("a")), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(Fnv1a64(std::string("foobar")), 0x85944171f73967e8ULL);
  EXPECT_EQ(HashToHex(0xaf63dc4c8601ec8cULL), "af63dc4c8601ec8c");
  // Chaining equals hashing the concatenation.
  EXPECT_EQ(Fnv1a64(std::string("bar"), Fnv1a64(std::string("foo"))),
            Fnv1a64(std::string("foobar")));
}

CampaignConfig BaseConfig() {
  CampaignConfig c;
  c.filar_length_m = 2.0;
  c.filar_separation_m = 1.8;
  c.rig_mass_kg = 1.25;
  c.aircraft_mass_kg = 5.5;
  return c;
}

TEST(Cache, KeyHasEveryFitInputAndNothingElse) {
  const CampaignConfig base = BaseConfig();
  const std::string key = FitFingerprint(base, TraceRole::kAircraft, std::nullopt);
  auto changed = [&](void (*edit)(CampaignConfig*)) {
    CampaignConfig c = base;
    edit(&c);
    return FitFingerprint(c, TraceRole::kAircraft, std::nullopt) != key;
  };
  // Fit inputs: every one changes the key.
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->filar_length_m = 2.001; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->filar_separation_m = 1.7; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->rig_mass_kg = 1.3; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->aircraft_mass_kg = 5.6; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->gravity_mps2 = 9.81; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->uncertainties.filar_length_std_m = 0.01; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->fit.model = PendulumModel::kJardin; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->fit.max_amplitude_deg = 20.0; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->fit.quality.max_rms_over_noise = 2.0; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->imu.format.gyro_unit = RateUnit::kDegPerS; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->imu.swing_axis_auto = false; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->imu.gyro_scale_std = 0.005; }));
  EXPECT_TRUE(changed([](CampaignConfig* c) { c->imu.imu_to_body(0, 0) = -1.0; }));
  // Not fit inputs: the rig inertia, pitch source, ellipse, units.
  EXPECT_FALSE(changed([](CampaignConfig* c) { c->rig_inertia.inertia_kg_m2 = 0.3; }));
  EXPECT_FALSE(
      changed([](CampaignConfig* c) { c->rig_inertia.kind = RigInertiaSpec::Kind::kTare; }));
  EXPECT_FALSE(changed([](CampaignConfig* c) { c->runs.pitch_source = PitchSource::kMeasured; }));
  EXPECT_FALSE(changed([](CampaignConfig* c) { c->ellipse.bootstrap = 10; }));
  EXPECT_FALSE(changed([](CampaignConfig* c) { c->units = DisplayUnits::kImperial; }));
  // A tare log is fitted with the rig mass alone: the aircraft mass is not in its key.
  CampaignConfig heavier = base;
  heavier.aircraft_mass_kg = 9.0;
  EXPECT_EQ(FitFingerprint(base, TraceRole::kTare, std::nullopt),
            FitFingerprint(heavier, TraceRole::kTare, std::nullopt));
  EXPECT_NE(FitFingerprint(base, TraceRole::kTare, std::nullopt), key);
  // The window override of this file.
  EXPECT_NE(FitFingerprint(base, TraceRole::kAircraft, std::array<double, 2>{1.0, 30.0}), key);
  // The key mixes content and settings.
  EXPECT_NE(CacheKey("0123456789abcdef", key), CacheKey("0123456789abcdee", key));
}

TEST(Cache, StoreAndLoadRoundTrip) {
  char tmpl[] = "/tmp/bifilar_cache_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const TraceCache cache(dir + "/cache");
  TraceRecord r;
  r.file = "pitch_0/trial_1.csv";
  r.status = TraceStatus::kRejected;
  r.message = "residuals not white";
  r.inertia_total_kg_m2 = 4.1;
  r.inertia_total_std_kg_m2 = 2e-5;
  r.window_s = {3.5, 44.0};
  r.amplitude_deg = {25.0, 9.0};
  r.pitch_measured_deg = 0.3;
  r.budget = {{"filar_length", 1e-3}, {"mass", 2e-4}};
  r.budget_total_std_kg_m2 = 1.02e-3;
  r.flags = {"residual_not_white"};
  r.iterations = 7;
  r.model = "full";
  TraceRecord loaded;
  std::string problem;
  EXPECT_FALSE(cache.Load("0000000000000001", "00000000000000aa", &loaded, &problem));
  EXPECT_TRUE(problem.empty()) << problem;
  cache.Store("0000000000000001", "00000000000000aa", r);
  ASSERT_TRUE(cache.Load("0000000000000001", "00000000000000aa", &loaded, &problem)) << problem;
  EXPECT_EQ(loaded.file, r.file);
  EXPECT_EQ(loaded.status, TraceStatus::kRejected);
  EXPECT_EQ(loaded.message, r.message);
  EXPECT_DOUBLE_EQ(loaded.inertia_total_kg_m2, 4.1);
  EXPECT_DOUBLE_EQ(loaded.window_s[1], 44.0);
  EXPECT_DOUBLE_EQ(*loaded.pitch_measured_deg, 0.3);
  EXPECT_TRUE(std::isnan(loaded.drag_coeff_kg_m2));  // null stays "not applicable"
  ASSERT_EQ(loaded.budget.size(), 2u);
  EXPECT_DOUBLE_EQ(loaded.budget_total_std_kg_m2, 1.02e-3);
  EXPECT_EQ(loaded.flags, r.flags);
  EXPECT_EQ(loaded.iterations, 7);
  // A damaged entry is refused with a reason, not an error.
  std::ofstream(cache.EntryPath("0000000000000002")) << "{ not json";
  EXPECT_FALSE(cache.Load("0000000000000002", "00000000000000aa", &loaded, &problem));
  EXPECT_NE(problem.find("not valid JSON"), std::string::npos) << problem;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

// issue 33 item 6: a fit abandoned by the time guard depends on the machine's speed; it is
// never stored, so a faster run fits the log again instead of replaying the error.
TEST(Cache, TimeGuardRecordIsNotStored) {
  char tmpl[] = "/tmp/bifilar_cache_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const TraceCache cache(dir + "/cache");
  TraceRecord r;
  r.file = "pitch_0/trial_1.csv";
  r.status = TraceStatus::kError;
  r.message = "abandoned by the time guard after 600.1 s of CPU time";
  r.flags = {"time_guard"};
  cache.Store("0000000000000003", "00000000000000aa", r);
  TraceRecord loaded;
  std::string problem;
  EXPECT_FALSE(cache.Load("0000000000000003", "00000000000000aa", &loaded, &problem));
  EXPECT_TRUE(problem.empty()) << problem;
  EXPECT_FALSE(std::filesystem::exists(cache.EntryPath("0000000000000003")));
  r.flags = {"solver_bound"};  // a work bound is the same on every machine: stored
  r.status = TraceStatus::kRejected;
  cache.Store("0000000000000003", "00000000000000aa", r);
  EXPECT_TRUE(cache.Load("0000000000000003", "00000000000000aa", &loaded, &problem)) << problem;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

// issue 9 item 6: the cache was trusted blindly. Each tampering is refused with its reason.
TEST(Cache, EntryProvesItsKeyAndIntegrity) {
  char tmpl[] = "/tmp/bifilar_cache_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const TraceCache cache(dir + "/cache");
  const TraceRecord r = OkRecord();
  const std::string key = "00000000000000k1", other = "00000000000000k2", hash = "00000000000000aa";
  cache.Store(key, hash, r);
  cache.Store(other, "00000000000000bb", r);
  const std::string good = test_support::ReadFile(cache.EntryPath(key));
  TraceRecord loaded;
  std::string problem;
  auto refused = [&](const std::string& text, std::string content_hash = "") {
    if (content_hash.empty()) content_hash = hash;
    std::ofstream(cache.EntryPath(key)) << text;
    const bool ok = cache.Load(key, content_hash, &loaded, &problem);
    return !ok && !problem.empty() ? problem : std::string();
  };
  EXPECT_EQ(refused(good), "");
  EXPECT_TRUE(cache.Load(key, hash, &loaded, &problem)) << problem;
  // A value scaled by 0.9: the checksum no longer matches.
  std::string scaled = good;
  scaled.replace(scaled.find("4.1"), 3, "3.69");
  EXPECT_NE(refused(scaled).find("checksum mismatch"), std::string::npos);
  // Another trace's entry copied into this key's file.
  EXPECT_NE(refused(test_support::ReadFile(cache.EntryPath(other))).find("belongs to key"),
            std::string::npos);
  // The right key, a different log content (the log was replaced).
  EXPECT_NE(refused(good, "00000000000000cc").find("another log"), std::string::npos);
  // NaN and a negative inertia written over the value (checksum fixed up or not): refused.
  std::string nan_entry = good;
  nan_entry.replace(nan_entry.find("4.1"), 3, "NaN");
  EXPECT_NE(refused(nan_entry), "");
  std::string negative = good;
  negative.replace(negative.find("4.1"), 3, "-5");
  EXPECT_NE(refused(negative), "");
  // A record without the envelope (an older entry, or hand-made).
  EXPECT_NE(refused(R"({"status": "ok", "inertia_total_kg_m2": 4.1})")
                .find("format " + std::to_string(TraceCache::kFormat)),
            std::string::npos);
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

// An entry is read by the one reader of a trace record (TraceRecordFromJson): an entry that lacks
// a key the writer writes (an older format) is refused naming the key even with its checksum
// fixed up, and one holding a number beyond a double is refused as not valid JSON; both are
// refitted.
TEST(Cache, AnEntryLackingAKeyIsRefusedNamingIt) {
  char tmpl[] = "/tmp/bifilar_cache_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const TraceCache cache(dir + "/cache");
  TraceRecord r = OkRecord();
  r.period_s = 2.49;
  const std::string key = "00000000000000k1", hash = "00000000000000aa";
  cache.Store(key, hash, r);
  const nlohmann::json good = nlohmann::json::parse(test_support::ReadFile(cache.EntryPath(key)));
  // The entry as TraceCache::Store writes it, with its checksum made to match `record`.
  const auto write = [&](nlohmann::json record, const std::string& text_of_inertia = "") {
    nlohmann::json entry = good;
    entry["record"] = record;
    entry["checksum"] = HashToHex(
        Fnv1a64(key + ";" + hash + ";" + ProgramVersion() + ";" + record.dump(-1, ' ', false)));
    std::string text = entry.dump(1);
    if (!text_of_inertia.empty()) {
      const std::string written = "\"inertia_total_kg_m2\": null";
      text.replace(text.find(written), written.size(),
                   "\"inertia_total_kg_m2\": " + text_of_inertia);
    }
    std::ofstream(cache.EntryPath(key)) << text;
    TraceRecord loaded;
    std::string problem;
    return cache.Load(key, hash, &loaded, &problem) ? std::string("loaded") : problem;
  };
  nlohmann::json record = good["record"];
  EXPECT_EQ(write(record), "loaded");  // the checksum made here is the cache's
  record.erase("period_s");
  EXPECT_NE(write(record).find("cache entry refused ('period_s' is missing)"), std::string::npos);
  record = good["record"];
  record["uncertainty"].erase("hac_bandwidth");
  EXPECT_NE(write(record).find("('uncertainty.hac_bandwidth' is missing)"), std::string::npos);
  // A number beyond a double (1e999) is refused by the JSON parser (number overflow), so the
  // entry is refitted, never read as infinity; the checksum is of the record as it would parse.
  record = good["record"];
  record["inertia_total_kg_m2"] = std::numeric_limits<double>::infinity();
  const std::string infinite = write(record, "1e999");
  EXPECT_NE(infinite.find("cache entry refused (not valid JSON)"), std::string::npos) << infinite;
  EXPECT_NE(infinite.find(cache.EntryPath(key)), std::string::npos) << infinite;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace
}  // namespace bifilar
