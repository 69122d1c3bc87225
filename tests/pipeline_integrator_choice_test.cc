// The fit's integrator in the user's hands (`fit.integrator: rk853 | cvodes`, `--integrator`):
// the committed sample campaign (sample_runs/prandtl_d, 57 simulated logs) processed with each
// method gives the same answer, the choice is part of the cache key, and an unknown method is a
// config error naming the allowed values.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/config/config.h"
#include "pipeline/store/cache.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

const std::string kSampleConfig = std::string(BIFILAR_SOURCE_DIR) + "/configs/prandtl_d.yaml";

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_integrator_choice_XXXXXX";
  return mkdtemp(tmpl);
}

struct Processed {
  CampaignResult result;
  std::string summary;  // the console summary without its timing and cache lines
};

Processed Process(IntegratorMethod method, const std::string& out_dir) {
  CampaignConfig config = LoadCampaignConfig(kSampleConfig);
  config.fit.integrator = method;
  CampaignOptions options;
  options.out_dir = out_dir;
  options.jobs = 2;
  options.force = true;
  options.figures = false;
  options.write_report = false;
  Processed p;
  p.result = RunCampaign(config, options);
  std::ostringstream text;
  PrintCampaignSummary(config, p.result, text);
  std::istringstream lines(text.str());
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("Traces:", 0) == 0) continue;  // wall time and cache reuse differ
    p.summary += line + "\n";
  }
  return p;
}

// Issue 10 item 3. Both fits integrate to ~1e-8 rad/s (rk853 at rel 1e-8; cvodes at 0.3x that,
// IntegratorOptions::WithMethod), five orders below the 0.25 deg/s gyro noise; observed
// difference of I 3.4e-8 relative at most. Bound: 1e-6 relative, as the issue asks.
TEST(IntegratorChoice, SampleCampaignAgreesBetweenMethods) {
  constexpr double kRelTol = 1e-6;
  const std::string dir = TempDir();
  const Processed rk = Process(IntegratorMethod::kRungeKutta, dir + "/rk853");
  const Processed cv = Process(IntegratorMethod::kCvodes, dir + "/cvodes");
  ASSERT_EQ(rk.result.traces.size(), 57u);
  ASSERT_EQ(cv.result.traces.size(), rk.result.traces.size());
  std::map<std::string, const TraceRecord*> by_file;
  for (const TraceRecord& r : rk.result.traces) by_file[r.file] = &r;
  for (const TraceRecord& c : cv.result.traces) {
    ASSERT_EQ(by_file.count(c.file), 1u) << c.file;
    const TraceRecord& r = *by_file[c.file];
    ASSERT_TRUE(r.ok()) << r.file << ": " << r.message;
    ASSERT_TRUE(c.ok()) << c.file << ": " << c.message;
    EXPECT_NEAR(c.inertia_total_kg_m2 / r.inertia_total_kg_m2, 1.0, kRelTol) << c.file;
    // The HAC std depends on the residuals through an integer bandwidth: allow 0.1 %.
    EXPECT_NEAR(c.inertia_total_std_kg_m2 / r.inertia_total_std_kg_m2, 1.0, 1e-3) << c.file;
    EXPECT_NE(c.cache_key, r.cache_key) << c.file;  // the method is part of the key
  }
  ASSERT_TRUE(rk.result.ellipse_fit.has_value());
  ASSERT_TRUE(cv.result.ellipse_fit.has_value());
  // Same Table 2, Table 1 and rig inertia to every printed digit.
  EXPECT_EQ(cv.summary, rk.summary);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST(IntegratorChoice, ConfigKeyAndErrors) {
  const std::string dir = TempDir();
  const std::string yaml = dir + "/c.yaml";
  const auto write = [&](const std::string& fit_section) {
    std::ofstream(yaml) << "rig: {filar_length_m: 2.0, filar_separation_m: 0.88, mass_kg: 6.0}\n"
                           "imu:\n  time: {column: t, unit: s}\n"
                           "  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
                        << fit_section;
  };
  ConfigLoadOptions fit_only;
  fit_only.require_runs = false;

  write("");
  EXPECT_EQ(LoadCampaignConfig(yaml, fit_only).fit.integrator, IntegratorMethod::kRungeKutta);
  write("fit: {integrator: cvodes}\n");
  EXPECT_EQ(LoadCampaignConfig(yaml, fit_only).fit.integrator, IntegratorMethod::kCvodes);
  write("fit: {integrator: rk853}\n");
  EXPECT_EQ(LoadCampaignConfig(yaml, fit_only).fit.integrator, IntegratorMethod::kRungeKutta);

  write("fit:\n  integrator: euler\n");
  try {
    LoadCampaignConfig(yaml, fit_only);
    ADD_FAILURE() << "fit.integrator: euler was accepted";
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(yaml), std::string::npos) << what;
    EXPECT_NE(what.find("fit.integrator"), std::string::npos) << what;
    EXPECT_NE(what.find("rk853 or cvodes"), std::string::npos) << what;
    EXPECT_NE(what.find("euler"), std::string::npos) << what;
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// The method reaches the fingerprint; the default leaves it as earlier versions wrote it, so
// their caches stay valid.
TEST(IntegratorChoice, CacheKeyCarriesTheMethod) {
  CampaignConfig config = LoadCampaignConfig(kSampleConfig);
  const std::string rk = FitFingerprint(config, TraceRole::kAircraft, std::nullopt);
  config.fit.integrator = IntegratorMethod::kCvodes;
  const std::string cv = FitFingerprint(config, TraceRole::kAircraft, std::nullopt);
  EXPECT_NE(rk, cv);
  // Both methods named (cache format 3: the key is the canonical text of the options).
  EXPECT_NE(rk.find("fit.integrator=rk853;"), std::string::npos) << rk;
  EXPECT_NE(cv.find("fit.integrator=cvodes;"), std::string::npos) << cv;
}

}  // namespace
}  // namespace bifilar
