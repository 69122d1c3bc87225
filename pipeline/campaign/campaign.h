// A test campaign: a folder of IMU logs (a few trials per pitch angle) plus the rig's tare logs
// -> every trace fitted (in parallel, cached), the rig subtracted, per-angle statistics, the
// ellipse of inertia, and results.json / traces.csv / angles.csv / report.html in OUT.
// RunCampaign's steps: discover (pipeline/campaign/run_discovery.h) -> calibrate the rig geometry
// when rig.calibration is set (pipeline/campaign/calibration.h) -> fit traces (in parallel,
// base/parallel_runner.h, cached) -> tare -> group by angle -> ellipse -> write
// (pipeline/store/output_set.h, atomically: base/atomic_file.h).
// Conventions: docs/physics.md §2 (tare: I_aircraft = I_total - I_rig), §3 (pitch, ellipse).
#pragma once

#include <atomic>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/ellipse.h"
#include "fit/tensor.h"
#include "pipeline/campaign/run_discovery.h"  // RunFile, DiscoverRuns
#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {

// Fits one trace; ProcessTrace in production, a fake in tests.
using TraceFitFunction = std::function<TraceRecord(const CampaignConfig&, const std::string& path,
                                                   const TraceProcessOptions&)>;

constexpr int kMaxJobs = 256;  // limit of CampaignOptions::jobs (--jobs)

struct CampaignOptions {
  std::string out_dir;               // output folder (created); an existing non-folder is an error
  int jobs = 0;                      // worker threads; 0 = hardware concurrency; <= kMaxJobs
  bool force = false;                // ignore the cache (refit everything)
  bool write_report = true;          // report.html (needs the figures)
  bool figures = true;               // draw per-trace fit figures and Fig. 3/4
  std::ostream* progress = nullptr;  // progress lines / bar; nullptr = quiet
  bool progress_bar = false;         // redraw one line ('\r') instead of one line per trace
  TraceFitFunction fit_function;     // empty = ProcessTrace
  // Ctrl-C (base/interrupt.h): when set, no further fit starts; fits running finish and are
  // cached, and RunCampaign throws CampaignInterrupted before writing any result. nullptr: none.
  const std::atomic<bool>* cancel = nullptr;
  // Called after each fit (from worker threads, serialised): fits done, fits planned, the
  // trace's progress line. Empty: none. Beside `progress`, for the Python module's callback.
  std::function<void(int done, int total, const std::string& line)> on_progress;

  bool Check(std::string* why) const;
};

// Runs the campaign and writes OUT/{results.json, traces.csv, angles.csv, report.html} (each
// atomically), OUT/cache/ and OUT/figures/. Throws UserError for config/usage problems (the CLI
// turns it into exit code 2), and when rig.calibration cannot be made (a reference swing that
// does not fit, named; no aircraft trace is fitted then); problems with single logs are error
// rows.
CampaignResult RunCampaign(const CampaignConfig& config, const CampaignOptions& options);

}  // namespace bifilar
