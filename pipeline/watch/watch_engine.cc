#include "pipeline/watch/watch_engine.h"

#include <algorithm>
#include <cmath>

#include "base/enum_names.h"
#include "base/json_number.h"
#include "base/statistics.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

constexpr EnumName<WatchVerdict> kWatchVerdictNames[] = {{WatchVerdict::kWaiting, "waiting"},
                                                         {WatchVerdict::kSwinging, "swinging"},
                                                         {WatchVerdict::kEnough, "enough"},
                                                         {WatchVerdict::kSwingAgain, "swing_again"},
                                                         {WatchVerdict::kFixRig, "fix_rig"}};

constexpr size_t kRecentSamples = 256;  // the ring behind the rate and noise before release
constexpr int kMinPointsToFit = 20;
// A swing has started when the recent rate's std exceeds this many times the one at rest.
constexpr double kReleaseNoiseRatio = 5.0;

bool HasFlag(const TraceRecord& r, const std::string& flag) {
  return std::find(r.flags.begin(), r.flags.end(), flag) != r.flags.end();
}

// The exponent p of relative std ~ cycles^-p from the last two updates of the swing, when they
// are far enough apart to say; 1.5 otherwise (a frequency measured over a longer record: the
// std falls as T^-3/2 for white noise at a fixed rate).
double DecayExponent(const std::vector<std::pair<double, double>>& history) {
  constexpr double kDefault = 1.5;
  if (history.size() < 2) return kDefault;
  const auto& [c1, r1] = history[history.size() - 2];
  const auto& [c2, r2] = history.back();
  if (!(c2 > c1 + 0.5) || !(r1 > 0) || !(r2 > 0)) return kDefault;
  const double p = -std::log(r2 / r1) / std::log(c2 / c1);
  return std::isfinite(p) ? std::clamp(p, 0.5, 3.0) : kDefault;
}

}  // namespace

const char* ToString(WatchVerdict verdict) { return EnumToString(kWatchVerdictNames, verdict); }
bool ParseWatchVerdict(const std::string& name, WatchVerdict* verdict) {
  return ParseEnum(kWatchVerdictNames, name, verdict);
}
std::string WatchVerdictAllowedValues() { return EnumAllowedValues(kWatchVerdictNames); }

bool WatchEngineOptions::Check(std::string* why) const {
  if (!(target_percent > 0 && target_percent <= 100)) {
    *why = "target percent " + Fmt("%g", target_percent) + "; must be in (0, 100]";
    return false;
  }
  if (!(update_interval_s > 0 && std::isfinite(update_interval_s))) {
    *why = "update interval " + Fmt("%g", update_interval_s) + " s; must be > 0";
    return false;
  }
  if (max_fit_samples < 200) {
    *why = "max fit samples " + std::to_string(max_fit_samples) + "; must be >= 200";
    return false;
  }
  if (!(agreement_sigmas > 0 && std::isfinite(agreement_sigmas))) {
    *why = "agreement sigmas " + Fmt("%g", agreement_sigmas) + "; must be > 0";
    return false;
  }
  return true;
}

nlohmann::json WatchUpdateToJson(const WatchUpdate& u) {
  nlohmann::json j;
  j["t_s"] = JsonNumber(u.t_s);
  j["samples"] = u.samples;
  j["rate_hz"] = JsonNumber(u.rate_hz);
  j["rate_noise_rad_per_s"] = JsonNumber(u.rate_noise_rad_per_s);
  j["swing"] = u.swing;
  j["cycles"] = JsonNumber(u.cycles);
  j["amplitude_deg"] = JsonNumber(u.amplitude_deg);
  j["period_s"] = JsonNumber(u.period_s);
  j["small_angle_inertia_kg_m2"] = JsonNumber(u.small_angle_inertia_kg_m2);
  j["inertia_kg_m2"] = JsonNumber(u.inertia_kg_m2);
  j["inertia_std_stat_kg_m2"] = JsonNumber(u.inertia_std_stat_kg_m2);
  j["inertia_std_total_kg_m2"] = JsonNumber(u.inertia_std_total_kg_m2);
  j["cycles_needed"] = JsonNumber(u.cycles_needed);
  j["fit_points"] = u.fit_points;
  j["block_size"] = u.block_size;
  j["verdict"] = ToString(u.verdict);
  j["reason"] = u.reason;
  j["earlier_swings_kg_m2"] = nlohmann::json::array();
  for (double i : u.earlier_swings_kg_m2) j["earlier_swings_kg_m2"].push_back(JsonNumber(i));
  j["repeat_agreement"] = u.repeat_agreement;
  return j;
}

WatchEngine::WatchEngine(const CampaignConfig& config, const WatchEngineOptions& options)
    : config_(config), options_(options) {
  std::string why;
  if (!options.Check(&why)) throw UserError("watch: " + why);
  recent_t_.reserve(kRecentSamples);
  recent_rate_.reserve(kRecentSamples * 3);
}

bool WatchEngine::Add(double t_s, const Eigen::Vector3d& gyro, const Eigen::Vector3d* accel) {
  if (samples_ == 0) has_accel_ = accel != nullptr;
  ++samples_;
  if (recent_t_.size() < kRecentSamples) {
    recent_t_.push_back(t_s);
    for (int k = 0; k < 3; ++k) recent_rate_.push_back(gyro[k]);
  } else {
    recent_t_[recent_next_] = t_s;
    for (int k = 0; k < 3; ++k) recent_rate_[recent_next_ * 3 + k] = gyro[k];
    recent_next_ = (recent_next_ + 1) % kRecentSamples;
  }
  const Eigen::Vector3d a = (has_accel_ && accel != nullptr) ? *accel : Eigen::Vector3d::Zero();
  if (block_ == 1) {
    points_.t_s.push_back(t_s);
    points_.gyro_in_imu.push_back(gyro);
    if (has_accel_) points_.accel_in_imu.push_back(a);
  } else {
    pending_t_ += t_s;
    pending_gyro_ += gyro;
    pending_accel_ += a;
    if (++pending_n_ == block_) {
      points_.t_s.push_back(pending_t_ / block_);
      points_.gyro_in_imu.push_back(pending_gyro_ / block_);
      if (has_accel_) points_.accel_in_imu.push_back(pending_accel_ / block_);
      pending_t_ = 0.0;
      pending_gyro_.setZero();
      pending_accel_.setZero();
      pending_n_ = 0;
    }
  }
  if (static_cast<int>(points_.size()) > options_.max_fit_samples) {
    // Merge while a point stays shorter than 1/32 of a period (its mean keeps the swing's shape
    // to 0.2 %); beyond, keep only the recent half of the points.
    const size_t n = points_.size();
    const double spacing = (points_.t_s.back() - points_.t_s.front()) / static_cast<double>(n - 1);
    if (std::isfinite(last_.period_s) && 2.0 * spacing > last_.period_s / 32.0) {
      DropOldestHalf();
    } else {
      MergePairs();
    }
  }
  if (std::isnan(next_update_t_)) next_update_t_ = t_s + options_.update_interval_s;
  return t_s >= next_update_t_;
}

// Halves the points: each new point is the mean of two neighbours (an odd last one stays the
// start of the block being filled), and the block size doubles.
void WatchEngine::MergePairs() {
  ImuData merged;
  const size_t n = points_.size();
  for (size_t i = 0; i + 1 < n; i += 2) {
    merged.t_s.push_back(0.5 * (points_.t_s[i] + points_.t_s[i + 1]));
    merged.gyro_in_imu.push_back(0.5 * (points_.gyro_in_imu[i] + points_.gyro_in_imu[i + 1]));
    if (has_accel_) {
      merged.accel_in_imu.push_back(0.5 * (points_.accel_in_imu[i] + points_.accel_in_imu[i + 1]));
    }
  }
  // The pending samples (fewer than block_) and an odd last point (block_ samples) start the
  // next block of 2 * block_ samples.
  if (n % 2 == 1) {
    pending_t_ += points_.t_s[n - 1] * block_;
    pending_gyro_ += points_.gyro_in_imu[n - 1] * block_;
    if (has_accel_) pending_accel_ += points_.accel_in_imu[n - 1] * block_;
    pending_n_ += block_;
  }
  points_ = std::move(merged);
  block_ *= 2;
}

void WatchEngine::DropOldestHalf() {
  const size_t half = points_.size() / 2;
  points_.t_s.erase(points_.t_s.begin(), points_.t_s.begin() + half);
  points_.gyro_in_imu.erase(points_.gyro_in_imu.begin(), points_.gyro_in_imu.begin() + half);
  if (has_accel_) {
    points_.accel_in_imu.erase(points_.accel_in_imu.begin(), points_.accel_in_imu.begin() + half);
  }
}

void WatchEngine::Recent(WatchUpdate* u) const {
  const size_t n = recent_t_.size();
  if (n < 2) return;
  const double t_first = *std::min_element(recent_t_.begin(), recent_t_.end());
  const double t_last = *std::max_element(recent_t_.begin(), recent_t_.end());
  if (t_last > t_first) u->rate_hz = static_cast<double>(n - 1) / (t_last - t_first);
  double noise = 0.0;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> axis;
    axis.reserve(n);
    for (size_t i = 0; i < n; ++i) axis.push_back(recent_rate_[i * 3 + k]);
    noise = std::max(noise, SampleStd(axis));
  }
  u->rate_noise_rad_per_s = noise;
}

WatchUpdate WatchEngine::Update() {
  WatchUpdate u;
  u.samples = samples_;
  u.t_s = points_.t_s.empty() ? NAN : points_.t_s.back();
  if (!recent_t_.empty()) {
    u.t_s = *std::max_element(recent_t_.begin(), recent_t_.end());
  }
  u.swing = static_cast<int>(swings_.size()) + 1;
  Recent(&u);
  u.fit_points = static_cast<int>(points_.size());
  u.block_size = block_;
  record_ = TraceRecord();
  if (u.fit_points >= kMinPointsToFit) {
    TraceProcessOptions process;
    process.display_name = options_.log_name;
    record_ = ProcessTraceData(config_, points_, options_.log_name, process);
  } else {
    record_.message = "too few samples yet";
  }
  u.period_s = record_.period_s;
  if (std::isfinite(record_.period_s) && record_.period_s > 0) {
    u.cycles = (record_.window_s[1] - record_.window_s[0]) / record_.period_s;
  }
  u.amplitude_deg = record_.amplitude_deg[1];
  u.small_angle_inertia_kg_m2 = record_.small_angle_inertia_total_kg_m2;
  if (record_.status != TraceStatus::kError) {
    u.inertia_kg_m2 = record_.inertia_total_kg_m2;
    u.inertia_std_stat_kg_m2 = record_.inertia_total_std_kg_m2;
    u.inertia_std_total_kg_m2 = record_.inertia_total_std_total_kg_m2;
  }
  Judge(&u);
  const double half_period = 0.5 * u.period_s;
  const double interval = std::isfinite(half_period) && half_period > 0
                              ? std::min(half_period, options_.update_interval_s)
                              : options_.update_interval_s;
  next_update_t_ = (std::isfinite(u.t_s) ? u.t_s : 0.0) + interval;
  last_ = u;
  CloseSwingIfEnded();
  return u;
}

void WatchEngine::Judge(WatchUpdate* u) {
  const double min_cycles = config_.fit.quality.min_periods + 1.0;
  if (record_.status == TraceStatus::kError || !std::isfinite(u->inertia_kg_m2)) {
    // Released, but too little of the swing for a fit yet: the rate is far above the noise
    // measured at rest.
    if (std::isfinite(rest_noise_) && u->rate_noise_rad_per_s > kReleaseNoiseRatio * rest_noise_) {
      u->verdict = WatchVerdict::kSwinging;
      u->reason =
          "released; the first fit needs " + Fmt("%g", min_cycles - 1.0) + " cycles of free swing" +
          (record_.message.empty() ? "" : " (" + WarningSummary(record_.message, 100) + ")");
      return;
    }
    if (std::isfinite(u->rate_noise_rad_per_s)) {
      rest_noise_ = std::isfinite(rest_noise_) ? std::min(rest_noise_, u->rate_noise_rad_per_s)
                                               : u->rate_noise_rad_per_s;
    }
    u->verdict = WatchVerdict::kWaiting;
    for (const WatchSwing& s : swings_) u->earlier_swings_kg_m2.push_back(s.inertia_kg_m2);
    u->reason =
        "waiting for release: rate noise " + Fmt("%.2g", u->rate_noise_rad_per_s) + " rad/s at " +
        Fmt("%.0f", u->rate_hz) + " Hz" +
        (swings_.empty() ? ""
                         : "; last swing I = " + Fmt("%.6g", swings_.back().inertia_kg_m2) +
                               Fmt(" +- %.2g kg m^2", swings_.back().inertia_std_stat_kg_m2)) +
        (record_.message.empty() ? "" : " (" + WarningSummary(record_.message, 100) + ")");
    return;
  }
  if (record_.status == TraceStatus::kRejected) {
    if (u->cycles < min_cycles) {
      u->verdict = WatchVerdict::kSwinging;
      u->reason = "too few cycles for the checks yet";
    } else {
      u->verdict = WatchVerdict::kFixRig;
      u->reason = WarningSummary(record_.message, 200);
    }
    return;
  }
  const double relative = u->inertia_std_stat_kg_m2 / u->inertia_kg_m2;
  history_.emplace_back(u->cycles, relative);
  const double target = options_.target_percent / 100.0;
  u->cycles_needed = 0.0;
  if (relative > target) {
    const double p = DecayExponent(history_);
    u->cycles_needed = std::max(0.0, u->cycles * std::pow(relative / target, 1.0 / p) - u->cycles);
  }
  // Repeats: this swing against each earlier one of the set-up.
  for (const WatchSwing& s : swings_) u->earlier_swings_kg_m2.push_back(s.inertia_kg_m2);
  for (const WatchSwing& s : swings_) {
    const double sigma = std::hypot(u->inertia_std_stat_kg_m2, s.inertia_std_stat_kg_m2);
    const double d = std::abs(u->inertia_kg_m2 - s.inertia_kg_m2) / sigma;
    if (d > options_.agreement_sigmas) {
      u->repeat_agreement = "disagrees by " + Fmt("%.1f", d) + " sigma with swing " +
                            Fmt("%.6g", s.inertia_kg_m2) + " kg m^2";
      break;
    }
    u->repeat_agreement = "agrees";
  }
  const std::string percent = "std " + Fmt("%.2f", 100.0 * relative) + " % of I, target " +
                              Fmt("%g", options_.target_percent) + " %";
  const std::string warning =
      record_.warnings.empty() ? "" : "; " + WarningSummary(record_.warnings.front(), 120);
  const bool swing_over =
      std::isfinite(u->period_s) && record_.window_s[1] < u->t_s - 2.0 * u->period_s;
  if (relative <= target) {
    u->verdict = WatchVerdict::kEnough;
    u->reason = percent + warning;
  } else if (HasFlag(record_, "amplitude_above_band")) {
    u->verdict = WatchVerdict::kSwingAgain;
    u->reason = "the release was above the amplitude band: release lower; " + percent;
  } else if (swing_over) {
    u->verdict = WatchVerdict::kSwingAgain;
    u->reason = "the swing died out at " + Fmt("%.1f", u->amplitude_deg) +
                " deg before the target (" + percent + "): swing again";
  } else {
    u->verdict = WatchVerdict::kSwinging;
    u->reason =
        percent + ", about " + Fmt("%.0f", std::ceil(u->cycles_needed)) + " more cycles" + warning;
  }
}

// A swing is over when its fitted window ends more than three periods before the last sample
// (the amplitude fell below the band and the body swings no more, or hangs at rest): its result
// is kept for the repeat comparison and the next fit starts after it.
void WatchEngine::CloseSwingIfEnded() {
  if (record_.status != TraceStatus::kOk || !std::isfinite(last_.period_s)) return;
  const double end = record_.window_s[1];
  if (!(end < last_.t_s - 3.0 * last_.period_s)) return;
  swings_.push_back({record_.inertia_total_kg_m2, record_.inertia_total_std_kg_m2, end});
  const auto first_after =
      std::upper_bound(points_.t_s.begin(), points_.t_s.end(), end) - points_.t_s.begin();
  points_.t_s.erase(points_.t_s.begin(), points_.t_s.begin() + first_after);
  points_.gyro_in_imu.erase(points_.gyro_in_imu.begin(), points_.gyro_in_imu.begin() + first_after);
  if (has_accel_) {
    points_.accel_in_imu.erase(points_.accel_in_imu.begin(),
                               points_.accel_in_imu.begin() + first_after);
  }
  history_.clear();
  rest_noise_ = NAN;
}

}  // namespace bifilar
