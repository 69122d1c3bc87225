// `bifilar watch` (issue 34): the moment of inertia while the body swings. WatchEngine takes IMU
// samples (SI, IMU axes: pendulum/imu_data.h) as they arrive and, at least once per half-cycle of
// data time, runs the trace processing that `bifilar fit` runs (pipeline/trace/trace_process.h
// ProcessTraceData: window, swing axis, full-model FitTrace, quality checks, uncertainty) on the
// swing so far, and turns its record into a WatchUpdate with a verdict.
//
// Cost is bounded: the swing so far is kept as at most max_fit_samples points. While the swing
// holds no more samples than that (about 40 s at 100 Hz with the default), the points are the
// samples themselves and an update is exactly `bifilar fit` on the log so far. Beyond it,
// neighbouring points are merged in pairs (block means of time, rate and specific force), so a
// point stands for 2, 4, 8, ... samples: the fit then sees block means whose noise is lower by
// the square root of the block size, so its statistical std stays close to the full-rate one,
// and the work per update and the memory stay constant however long the stream (a benchmark,
// bench/watch_bench.cc, measures it at 1 kHz). Points are merged only while a point spans less
// than 1/32 of the period (the block mean then keeps the swing's amplitude to 0.2 %); past that,
// the oldest half of the points is dropped instead, and the fit is of a bounded recent window. The
// final result is never from block means: it is the fit of the saved log
// (pipeline/watch/watch_run.h).
//
// Updates are scheduled by the samples' own time (not the wall clock), so the same stream always
// gives the same updates.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pendulum/imu_data.h"
#include "pipeline/config/config.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

enum class WatchVerdict { kWaiting, kSwinging, kEnough, kSwingAgain, kFixRig };
// "waiting", "swinging", "enough", "swing_again", "fix_rig"
const char* ToString(WatchVerdict verdict);
bool ParseWatchVerdict(const std::string& name, WatchVerdict* verdict);
std::string WatchVerdictAllowedValues();

struct WatchEngineOptions {
  // Target of the per-swing std of I (the fit's statistical and model-inadequacy std,
  // TraceRecord::inertia_total_std_kg_m2) relative to I (%); "enough" once below it. (0, 100],
  // default 0.5.
  double target_percent = 0.5;
  // Data time between updates before the period is known (s); afterwards half a period. > 0,
  // default 0.5.
  double update_interval_s = 0.5;
  // Points of the swing so far that one update fits (see the header comment). >= 200, default
  // 4096.
  int max_fit_samples = 4096;
  // Two swings of one set-up agree when their I differ by at most this many combined std. > 0,
  // default 2.
  double agreement_sigmas = 2.0;
  // Name of the log in the fit's messages (and its fit.windows entry).
  std::string log_name = "watch";

  bool Check(std::string* why) const;
};

// One update: what the terminal line, the JSON lines and the page show.
struct WatchUpdate {
  double t_s = NAN;                        // data time of the last sample (s)
  long samples = 0;                        // samples received so far
  double rate_hz = NAN;                    // IMU rate of the recent samples (Hz)
  double rate_noise_rad_per_s = NAN;       // std of the swing-axis rate over the recent samples
  int swing = 1;                           // number of the current swing (1, 2, ...)
  double cycles = 0.0;                     // cycles of the fitted window
  double amplitude_deg = NAN;              // amplitude at the end of the fitted window (deg)
  double period_s = NAN;                   // measured period (s)
  double small_angle_inertia_kg_m2 = NAN;  // the classic formula (a hand check, labelled)
  double inertia_kg_m2 = NAN;              // the full-model fit's I of everything suspended
  double inertia_std_stat_kg_m2 = NAN;     // per-swing std (HAC + model inadequacy)
  double inertia_std_total_kg_m2 = NAN;    // with the budget (L, D, m, g) in quadrature
  double cycles_needed = NAN;  // more cycles to reach target_percent (estimate); 0 when there
  int fit_points = 0;          // points the fit saw (samples, or block means beyond the bound)
  int block_size = 1;          // samples per point
  WatchVerdict verdict = WatchVerdict::kWaiting;
  std::string reason;  // why this verdict, in words
  // Repeats: the I of the earlier swings of this set-up, and whether this one agrees with them.
  std::vector<double> earlier_swings_kg_m2;
  std::string repeat_agreement;  // "" (no earlier swing), "agrees" or "disagrees by ..."
};

nlohmann::json WatchUpdateToJson(const WatchUpdate& update);

// A swing the engine closed (its amplitude died out, or the stream went on at rest after it).
struct WatchSwing {
  double inertia_kg_m2 = NAN;
  double inertia_std_stat_kg_m2 = NAN;
  double t_end_s = NAN;
};

class WatchEngine {
 public:
  // Throws UserError when options.Check fails.
  WatchEngine(const CampaignConfig& config, const WatchEngineOptions& options);

  // Adds one sample (t strictly after the last one's; finite values; the caller checks).
  // Returns true when an update is due: call Update().
  bool Add(double t_s, const Eigen::Vector3d& gyro_rad_per_s, const Eigen::Vector3d* accel_mps2);

  // Fits the swing so far and returns the update (also kept as last()).
  WatchUpdate Update();

  const WatchUpdate& last() const { return last_; }
  const TraceRecord& last_record() const { return record_; }
  const std::vector<WatchSwing>& swings() const { return swings_; }
  long samples() const { return samples_; }
  // The points the next fit sees (for the benchmark's memory count and the tests).
  const ImuData& points() const { return points_; }

 private:
  void MergePairs();
  void DropOldestHalf();
  void CloseSwingIfEnded();
  void Recent(WatchUpdate* u) const;
  void Judge(WatchUpdate* u);

  CampaignConfig config_;
  WatchEngineOptions options_;
  ImuData points_;  // the swing so far: samples, or block means of block_ samples
  int block_ = 1;
  // The block being filled (block_ > 1): sums and count.
  double pending_t_ = 0.0;
  Eigen::Vector3d pending_gyro_ = Eigen::Vector3d::Zero(), pending_accel_ = Eigen::Vector3d::Zero();
  int pending_n_ = 0;
  bool has_accel_ = false;
  long samples_ = 0;
  double next_update_t_ = NAN;
  // Recent samples for the rate and noise shown before release (a ring of the last ~2 s).
  std::vector<double> recent_t_, recent_rate_;
  size_t recent_next_ = 0;
  TraceRecord record_;
  WatchUpdate last_;
  std::vector<WatchSwing> swings_;
  std::vector<std::pair<double, double>> history_;  // (cycles, relative std) of this swing
  double rest_noise_ = NAN;  // the smallest recent rate std seen while waiting (rad/s)
};

}  // namespace bifilar
