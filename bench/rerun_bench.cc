// A rerun with every fit cached (issue 25, "Numbers to reach": at most 0.15 s for a 39-log
// campaign): `process` of the sample's 13 pitch angles from -60 to 60 deg x 3 trials (39 logs,
// plus its 3 tare logs), figures and report.html included, after a first run that fitted them.
// What it times is everything but the fits: discovery and log hashing, the cache, the ellipse,
// the output set and the report.
// Run: build/bench/bifilar_bench --benchmark_filter=CachedRerun
#include <unistd.h>

#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "pipeline/campaign/campaign.h"
#include "pipeline/config/config.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

void BM_CachedRerun39Logs(benchmark::State& state) {
  const fs::path source = fs::path(BIFILAR_SOURCE_DIR) / "sample_runs/prandtl_d/logs";
  const fs::path work =
      fs::temp_directory_path() / ("bifilar_rerun_bench_" + std::to_string(getpid()));
  fs::remove_all(work);
  for (int pitch = -60; pitch <= 60; pitch += 10) {
    const std::string name = "pitch_" + std::to_string(pitch);
    fs::create_directories(work / "logs" / name);
    fs::copy(source / name, work / "logs" / name, fs::copy_options::recursive);
  }
  ConfigLoadOptions load;
  load.runs_root = (work / "logs").string();
  const CampaignConfig config =
      LoadCampaignConfig(std::string(BIFILAR_SOURCE_DIR) + "/configs/prandtl_d.yaml", load);
  CampaignOptions options;
  options.out_dir = (work / "out").string();
  options.jobs = 2;
  const CampaignResult first = RunCampaign(config, options);  // fits every log once
  if (first.summary.n_traces != 42) state.SkipWithError("expected 39 logs + 3 tare logs");
  for (auto _ : state) {
    const CampaignResult rerun = RunCampaign(config, options);
    if (rerun.summary.n_fitted != 0) state.SkipWithError("a fit was not cached");
  }
  fs::remove_all(work);
}
BENCHMARK(BM_CachedRerun39Logs)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace bifilar
