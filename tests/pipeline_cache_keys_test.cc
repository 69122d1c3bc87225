// The cache key against every config key in turn (issue 36): each key documented in
// configs/README.md is changed, alone, to another valid value, and the trace's cache key must
// change exactly when that key can change the trace's fit record. The keys of fit.quality,
// fit.amplitude_sweep and fit.glitch come from their option tables (base/option_table.h), so a
// field added to a table is tested here without an edit; every other key is classified below,
// and a key documented in configs/README.md but not classified here fails the test.
//
// Not in the key (pipeline/store/cache.h says why): the rig inertia, rig.calibration's own keys
// (they act through the calibrated geometry, which is in the key: "calibrated geometry" below),
// aircraft.cg_m, aircraft.cg_std_m, gravity_off_earth, runs.*, ellipse.*, units, limits.max_log_mb.
#include <array>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/option_table.h"
#include "pipeline/store/cache.h"
#include "test_support.h"

namespace bifilar {
namespace {

using Window = std::optional<std::array<double, 2>>;

// One config key, how to change it, and whether the fit record can change with it.
struct KeyEdit {
  std::string key;  // dotted, as configs/README.md names it
  bool fit;         // true: the key can change the trace's fit record
  std::function<void(CampaignConfig*, Window*)> edit;
};

// A config as `process` loads one (rig, aircraft with a mass std, defaults elsewhere).
CampaignConfig Base() {
  CampaignConfig c;
  c.filar_length_m = 2.0;
  c.filar_separation_m = 1.8;
  c.rig_mass_kg = 1.25;
  c.aircraft_mass_kg = 5.5;
  c.aircraft_mass_std_kg = 0.01;
  c.runs.root = "/logs";
  c.runs.pattern = "pitch_{pitch_deg}/*.csv";
  return c;
}

// Every field of an options table of `fit`, changed within its bounds: a flag flipped, a count
// + 1, a number x 1.05 (the test checks that the config stays valid).
template <class Options>
void AddTableEdits(const std::string& section, Options FitConfig::*part,
                   std::vector<KeyEdit>* out) {
  for (const OptionField<Options>& row : Options::Fields()) {
    out->push_back(
        {"fit." + section + "." + row.key, true, [row, part](CampaignConfig* c, Window*) {
           Options& o = c->fit.*part;
           if (row.flag) {
             o.*row.flag = !(o.*row.flag);
           } else if (row.whole) {
             o.*row.whole += 1;
           } else {
             o.*row.real *= 1.05;
           }
         }});
  }
}

std::vector<KeyEdit> TableEdits() {
  std::vector<KeyEdit> edits;
  AddTableEdits("quality", &FitConfig::quality, &edits);
  AddTableEdits("amplitude_sweep", &FitConfig::sweep, &edits);
  AddTableEdits("glitch", &FitConfig::glitch, &edits);
  return edits;
}

using Edit = std::function<void(CampaignConfig*, Window*)>;
const Edit kSection = nullptr;  // a mapping whose keys are listed one by one

// Every other key (and the sections), classified. Sections with a meaning of their own (the
// presence of rig.uncertainties, `imu.accel: null`) have an edit.
std::vector<KeyEdit> OtherEdits() {
  return {
      // Top level.
      {"rig", false, kSection},
      {"aircraft", false, kSection},
      {"imu", false, kSection},
      {"runs", false, kSection},
      {"fit", false, kSection},
      {"ellipse", false, kSection},
      {"limits", false, kSection},
      {"gravity_mps2", true, [](CampaignConfig* c, Window*) { c->gravity_mps2 = 9.81; }},
      {"gravity_off_earth", false, [](CampaignConfig* c, Window*) { c->gravity_off_earth = true; }},
      {"units", false, [](CampaignConfig* c, Window*) { c->units = DisplayUnits::kImperial; }},
      // rig
      {"rig.filar_length_m", true, [](CampaignConfig* c, Window*) { c->filar_length_m = 2.001; }},
      {"rig.filar_separation_m", true,
       [](CampaignConfig* c, Window*) { c->filar_separation_m = 1.7; }},
      {"rig.mass_kg", true, [](CampaignConfig* c, Window*) { c->rig_mass_kg = 1.3; }},
      {"rig.inertia", false, [](CampaignConfig* c, Window*) { c->rig_inertia_given = false; }},
      {"rig.inertia.inertia_kg_m2", false,
       [](CampaignConfig* c, Window*) { c->rig_inertia.inertia_kg_m2 = 0.3; }},
      {"rig.inertia.table", false,
       [](CampaignConfig* c, Window*) {
         c->rig_inertia.kind = RigInertiaSpec::Kind::kTable;
         c->rig_inertia.table_kg_m2 = {{0.0, 0.2}, {90.0, 0.3}};
       }},
      {"rig.inertia.tare", false,
       [](CampaignConfig* c, Window*) {
         c->rig_inertia.kind = RigInertiaSpec::Kind::kTare;
         c->rig_inertia.tare_patterns = {"/tare/*.csv"};
       }},
      {"rig.inertia.inertia_std_kg_m2", false,
       [](CampaignConfig* c, Window*) { c->rig_inertia.inertia_std_kg_m2 = 0.01; }},
      // Present, even empty: replaces the assumed 1 mm on L and D by what it says.
      {"rig.uncertainties", true,
       [](CampaignConfig* c, Window*) { c->uncertainties.configured = true; }},
      {"rig.uncertainties.filar_length_std_m", true,
       [](CampaignConfig* c, Window*) { c->uncertainties.filar_length_std_m = 0.002; }},
      {"rig.uncertainties.filar_separation_std_m", true,
       [](CampaignConfig* c, Window*) { c->uncertainties.filar_separation_std_m = 0.002; }},
      {"rig.uncertainties.mass_std_kg", true,
       [](CampaignConfig* c, Window*) { c->uncertainties.mass_std_kg = 0.002; }},
      {"rig.uncertainties.gravity_std_mps2", true,
       [](CampaignConfig* c, Window*) { c->uncertainties.gravity_std_mps2 = 0.002; }},
      // rig.calibration acts through the calibrated geometry the campaign finds (below).
      {"rig.calibration", false, [](CampaignConfig* c, Window*) { c->calibration.enabled = true; }},
      {"rig.calibration.logs", false,
       [](CampaignConfig* c, Window*) { c->calibration.log_patterns = {"/ref/*.csv"}; }},
      {"rig.calibration.reference_inertia_kg_m2", false,
       [](CampaignConfig* c, Window*) { c->calibration.reference_inertia_kg_m2 = 0.5; }},
      {"rig.calibration.reference_inertia_std_kg_m2", false,
       [](CampaignConfig* c, Window*) { c->calibration.reference_inertia_std_kg_m2 = 0.001; }},
      {"rig.calibration.reference_mass_kg", false,
       [](CampaignConfig* c, Window*) { c->calibration.reference_mass_kg = 2.0; }},
      {"rig.calibration.rig_pitch_deg", false,
       [](CampaignConfig* c, Window*) { c->calibration.rig_pitch_deg = 10.0; }},
      {"calibrated geometry: applied", true,
       [](CampaignConfig* c, Window*) { c->geometry_calibration.applied = true; }},
      {"calibrated geometry: factor", true,
       [](CampaignConfig* c, Window*) {
         c->geometry_calibration.applied = true;
         c->geometry_calibration.factor = 1.01;
       }},
      {"calibrated geometry: factor_rel_std", true,
       [](CampaignConfig* c, Window*) {
         c->geometry_calibration.applied = true;
         c->geometry_calibration.factor_rel_std = 0.002;
       }},
      // aircraft (an aircraft log's; a tare log's key is tested apart)
      {"aircraft.mass_kg", true, [](CampaignConfig* c, Window*) { c->aircraft_mass_kg = 5.6; }},
      {"aircraft.mass_std_kg", true,
       [](CampaignConfig* c, Window*) { c->aircraft_mass_std_kg = 0.02; }},
      {"aircraft.cg_m", false,
       [](CampaignConfig* c, Window*) {
         c->aircraft_cg.cg_m = {0.01, 0.0, 0.02};
       }},
      {"aircraft.cg_std_m", false,
       [](CampaignConfig* c, Window*) {
         c->aircraft_cg.cg_std_m = {0.001, 0.001, 0.001};
       }},
      // imu: how the log is read and how the IMU hangs
      {"imu.time.column", true,
       [](CampaignConfig* c, Window*) { c->imu.format.time_column = "time"; }},
      {"imu.time.unit", true,
       [](CampaignConfig* c, Window*) { c->imu.format.time_unit = TimeUnit::kMilliseconds; }},
      {"imu.gyro.columns", true,
       [](CampaignConfig* c, Window*) { c->imu.format.gyro_columns[2] = "wz"; }},
      {"imu.gyro.unit", true,
       [](CampaignConfig* c, Window*) { c->imu.format.gyro_unit = RateUnit::kDegPerS; }},
      {"imu.gyro.scale_std", true,
       [](CampaignConfig* c, Window*) { c->imu.gyro_scale_std = 0.005; }},
      {"imu.accel", true,
       [](CampaignConfig* c, Window*) {
         c->imu.format.accel_columns = {"", "", ""};
       }},
      {"imu.accel.columns", true,
       [](CampaignConfig* c, Window*) { c->imu.format.accel_columns[0] = "fx"; }},
      {"imu.accel.unit", true,
       [](CampaignConfig* c, Window*) { c->imu.format.accel_unit = AccelUnit::kStandardGravity; }},
      {"imu.swing_axis", true, [](CampaignConfig* c, Window*) { c->imu.swing_axis_auto = false; }},
      {"imu.imu_to_body", true,
       [](CampaignConfig* c, Window*) {
         c->imu.imu_to_body << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // 90 deg about z
       }},
      {"imu.format", true,
       [](CampaignConfig* c, Window*) { c->imu.format.container = LogContainer::kUlog; }},
      {"imu.ulog.topic", true,
       [](CampaignConfig* c, Window*) { c->imu.format.ulog.topic = "sensor_gyro"; }},
      {"imu.ulog.multi_id", true,
       [](CampaignConfig* c, Window*) { c->imu.format.ulog.multi_id = 1; }},
      {"imu.ulog.time_field", true,
       [](CampaignConfig* c, Window*) { c->imu.format.ulog.time_field = "timestamp_sample"; }},
      {"imu.ulog.gyro_fields", true,
       [](CampaignConfig* c, Window*) { c->imu.format.ulog.gyro_fields[0] = "x"; }},
      {"imu.ulog.accel_fields", true,
       [](CampaignConfig* c, Window*) {
         c->imu.format.ulog.accel_fields = {"", "", ""};
       }},
      {"imu.dataflash.instance", true,
       [](CampaignConfig* c, Window*) { c->imu.dataflash_instance = 1; }},
      // runs: which files and which pitch the ellipse uses (set after the fit)
      {"runs.root", false, [](CampaignConfig* c, Window*) { c->runs.root = "/other"; }},
      {"runs.pattern", false,
       [](CampaignConfig* c, Window*) { c->runs.pattern = "p{pitch_deg}/*"; }},
      {"runs.table", false,
       [](CampaignConfig* c, Window*) {
         c->runs.pattern.clear();
         c->runs.table = "/logs/runs.csv";
       }},
      {"runs.pitch_source", false,
       [](CampaignConfig* c, Window*) { c->runs.pitch_source = PitchSource::kMeasured; }},
      {"runs.attitude_tolerance_deg", false,
       [](CampaignConfig* c, Window*) { c->runs.attitude_tolerance_deg = 5.0; }},
      // fit (the tables' keys are added from the tables)
      {"fit.model", true,
       [](CampaignConfig* c, Window*) { c->fit.model = PendulumModel::kJardin; }},
      {"fit.integrator", true,
       [](CampaignConfig* c, Window*) { c->fit.integrator = IntegratorMethod::kCvodes; }},
      // The file's entry of fit.windows reaches the key as its window.
      {"fit.windows", true,
       [](CampaignConfig*, Window* w) {
         *w = std::array<double, 2>{1.0, 30.0};
       }},
      {"fit.max_amplitude_deg", true,
       [](CampaignConfig* c, Window*) { c->fit.max_amplitude_deg = 20.0; }},
      {"fit.min_amplitude_deg", true,
       [](CampaignConfig* c, Window*) { c->fit.min_amplitude_deg = 2.0; }},
      // ellipse
      {"ellipse.bootstrap", false, [](CampaignConfig* c, Window*) { c->ellipse.bootstrap = 500; }},
      {"ellipse.seed", false, [](CampaignConfig* c, Window*) { c->ellipse.seed = 7; }},
      {"ellipse.confidence", false,
       [](CampaignConfig* c, Window*) { c->ellipse.confidence = 0.9; }},
      {"ellipse.covariance", false,
       [](CampaignConfig* c, Window*) {
         c->ellipse.covariance = EllipseCovariance::kPointResiduals;
       }},
      {"ellipse.min_angles", false, [](CampaignConfig* c, Window*) { c->ellipse.min_angles = 4; }},
      // limits: a log beyond max_log_mb is never read (no key); a .csv.gz beyond the
      // decompression cap is an error record, which is cached.
      {"limits.max_log_mb", false, [](CampaignConfig* c, Window*) { c->limits.max_log_mb = 10; }},
      {"limits.max_decompressed_log_mb", true,
       [](CampaignConfig* c, Window*) { c->limits.max_decompressed_log_mb = 10; }},
  };
}

// The keys configs/README.md documents: the rows "| `key` |" of its tables under the headings
// "## Top level", "## `section`" and "### `section.sub` ...", up to the simulation specs.
std::set<std::string> DocumentedKeys() {
  const std::string text =
      test_support::ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/configs/README.md");
  std::set<std::string> keys;
  std::string section;
  bool in_keys = false;
  const std::regex heading(R"(^#{2,3} (.*)$)"), named(R"(^`([a-z_.]+)`)"),
      row(R"(^\| `([a-z_.]+)` \|)");
  std::istringstream in(text);
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_search(line, m, heading)) {
      const std::string title = m[1];
      if (title.rfind("Simulated", 0) == 0) break;
      std::smatch n;
      in_keys = title == "Top level" || std::regex_search(title, n, named);
      section = title == "Top level" || !in_keys ? "" : std::string(n[1]) + ".";
      continue;
    }
    if (in_keys && std::regex_search(line, m, row)) keys.insert(section + std::string(m[1]));
  }
  return keys;
}

TEST(CacheKeys, EveryConfigKeyChangesTheKeyExactlyWhenTheFitCan) {
  std::vector<KeyEdit> edits = TableEdits();
  const size_t table_keys = edits.size();
  for (KeyEdit& e : OtherEdits()) edits.push_back(std::move(e));
  EXPECT_EQ(table_keys, TraceQualityOptions::Fields().size() +
                            AmplitudeSweepOptions::Fields().size() +
                            GlitchOptions::Fields().size());

  const CampaignConfig base = Base();
  std::string why;
  ASSERT_TRUE(base.Check(&why)) << why;
  const std::string key = FitFingerprint(base, TraceRole::kAircraft, std::nullopt);
  std::set<std::string> tested;
  for (const KeyEdit& e : edits) {
    EXPECT_TRUE(tested.insert(e.key).second) << e.key << " listed twice";
    if (!e.edit) continue;
    CampaignConfig c = base;
    Window window;
    e.edit(&c, &window);
    if (e.key.rfind("fit.", 0) == 0) {
      EXPECT_TRUE(c.fit.Check(&why)) << e.key << ": " << why;
    }
    const bool changed = FitFingerprint(c, TraceRole::kAircraft, window) != key;
    EXPECT_EQ(changed, e.fit) << e.key
                              << (e.fit ? " can change the fit but not the cache key"
                                        : " changes the cache key but not the fit");
  }
  // A tare log swings the rig alone: the aircraft's mass and its std are not in its key.
  const std::string tare_key = FitFingerprint(base, TraceRole::kTare, std::nullopt);
  EXPECT_NE(tare_key, key);
  for (const char* k : {"aircraft.mass_kg", "aircraft.mass_std_kg"}) {
    for (const KeyEdit& e : edits) {
      if (e.key != k) continue;
      CampaignConfig c = base;
      Window window;
      e.edit(&c, &window);
      EXPECT_EQ(FitFingerprint(c, TraceRole::kTare, window), tare_key) << k;
    }
  }
  // The list is complete: every key configs/README.md documents is classified above, and every
  // table key is documented there.
  const std::set<std::string> documented = DocumentedKeys();
  EXPECT_GT(documented.size(), 60u);
  for (const std::string& k : documented) EXPECT_TRUE(tested.count(k)) << k << " is not classified";
  for (size_t i = 0; i < table_keys; ++i) {
    EXPECT_TRUE(documented.count(edits[i].key)) << edits[i].key << " is not in configs/README.md";
  }
}

// The key is the canonical text of the values: equal configs, equal keys; and it names the
// options by their config keys, from the tables.
TEST(CacheKeys, KeyIsTheCanonicalTextOfTheOptions) {
  const CampaignConfig a = Base();
  CampaignConfig b = Base();
  b.fit.quality.max_rms_over_noise = 3.5;
  b.fit.quality.max_rms_over_noise = 3.0;  // back to the same value
  EXPECT_EQ(FitFingerprint(a, TraceRole::kAircraft, std::nullopt),
            FitFingerprint(b, TraceRole::kAircraft, std::nullopt));
  const std::string text = FitFingerprint(a, TraceRole::kAircraft, std::nullopt);
  for (const char* part : {"fit.quality.whiteness_lags=10;", "fit.amplitude_sweep.max_bands=6;",
                           "fit.glitch.enabled=true;", "fit.quality.max_rms_over_noise=3;"}) {
    EXPECT_NE(text.find(part), std::string::npos) << part << " not in " << text;
  }
}

}  // namespace
}  // namespace bifilar
