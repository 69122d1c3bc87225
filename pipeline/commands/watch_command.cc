#include "pipeline/commands/watch_command.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include "base/interrupt.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/logs/format_guess.h"
#include "pipeline/records/results_json.h"
#include "pipeline/watch/saved_log.h"
#include "pipeline/watch/watch_server.h"
#include "pipeline/watch/watch_source.h"

namespace bifilar {
namespace {

using Clock = std::chrono::steady_clock;

// The state of one watch: the source, the log being written and its engine.
struct Watch {
  const WatchCommandOptions& o;
  CampaignConfig config;
  std::unique_ptr<WatchSource> source;
  std::unique_ptr<SavedLog> log;
  std::unique_ptr<WatchEngine> engine;
  WatchCommandResult* result;
  std::string next_save_path;

  void Event(const std::string& text) const {
    if (o.on_event) o.on_event(text);
  }

  void StartLog() {
    const std::string path =
        next_save_path.empty() ? DefaultSavedLogPath(o.config_path) : next_save_path;
    next_save_path.clear();
    log = std::make_unique<SavedLog>(path, config.imu.format, source->simulated_marker());
    engine = std::make_unique<WatchEngine>(config, o.engine);
    result->logs.push_back({path, 0, 0, std::nullopt});
    Event("saving every sample to " + path + " (" + source->format_description() + ")");
  }

  // Closes the log being written and fits it as `bifilar fit` does.
  void FinishLog() {
    if (log == nullptr) return;
    log->Flush();
    WatchLogResult& r = result->logs.back();
    r.samples = log->samples();
    r.rejected = log->rejected();
    log.reset();
    engine.reset();
    if (r.samples == 0) return;
    FitCommandOptions fit;
    fit.config_path = o.config_path;
    fit.logs = {r.path};
    FitCommandResult fitted = RunFit(fit);
    if (!fitted.records.empty()) r.record = fitted.records.front();
  }

  // Returns false when the watch should end (--cycles, --stop-at-target).
  bool Take(const std::vector<WatchSample>& samples, const std::vector<RejectedLine>& rejected) {
    if ((!samples.empty() || !rejected.empty()) && log == nullptr) StartLog();
    for (const RejectedLine& line : rejected) log->Reject(line);
    bool go_on = true;
    for (const WatchSample& s : samples) {
      const WatchSample back = log->Write(s);
      if (!go_on) continue;  // the watch ends, but every sample received is saved
      if (!engine->Add(back.t_s, back.gyro_rad_per_s,
                       back.has_accel ? &back.accel_mps2 : nullptr)) {
        continue;
      }
      log->Flush();
      const WatchUpdate u = engine->Update();
      result->updates.push_back(u);
      result->last_update = u;
      if (o.on_update) o.on_update(u);
      if (o.stop_after_cycles > 0 && u.verdict != WatchVerdict::kWaiting &&
          u.cycles >= o.stop_after_cycles) {
        result->end_reason = std::to_string(o.stop_after_cycles) + " cycles reached";
        go_on = false;
      }
      if (o.stop_at_target && u.verdict == WatchVerdict::kEnough) {
        result->end_reason = "target reached";
        go_on = false;
      }
    }
    if (log != nullptr) log->Flush();
    return go_on;
  }
};

void CheckOptions(const WatchCommandOptions& o) {
  std::string why;
  if (!o.engine.Check(&why)) throw UserError("watch: " + why);
  if (!(o.counter_rate_hz >= 0 && std::isfinite(o.counter_rate_hz))) {
    throw UserError("watch: --counter-rate-hz " + Fmt("%g", o.counter_rate_hz) + "; must be > 0");
  }
  if (o.stop_after_cycles < 0) throw UserError("watch: --cycles must be >= 1");
  if (!(o.idle_end_s >= 0) || !(o.idle_warn_s > 0)) {
    throw UserError("watch: --idle-end must be >= 0 s");
  }
}

bool GuessFormat(const std::string& text, ImuFormat* format, std::string* why) {
  const FormatGuess guess = GuessCsvFormat(text);
  if (!guess.found) {
    *why = guess.why;
    return false;
  }
  *format = guess.format;
  return true;
}

// After a disconnect: tries to open the source again every second until it opens (true), or
// Ctrl-C, the caller's stop or --idle-end (false, with the end reason).
bool Reconnect(Watch* w, Clock::time_point since) {
  const WatchCommandOptions& o = w->o;
  bool said = false;
  while (true) {
    if (ProcessInterruptFlag().load() || (o.keep_going && !o.keep_going())) {
      w->result->interrupted = ProcessInterruptFlag().load();
      w->result->end_reason = w->result->interrupted ? "interrupted (Ctrl-C)" : "stopped";
      return false;
    }
    const double waited = std::chrono::duration<double>(Clock::now() - since).count();
    if (o.idle_end_s > 0 && waited > o.idle_end_s) {
      w->result->end_reason = "disconnected for " + Fmt("%g", o.idle_end_s) + " s";
      return false;
    }
    std::string why;
    if (w->source->Reconnect(&why)) break;
    if (!said) w->Event("reconnecting to " + w->source->Describe() + " every second (" + why + ")");
    said = true;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  w->Event("reconnected to " + w->source->Describe() +
           (o.append_on_reconnect ? ": appending to the same log" : ": starting a new log"));
  if (!o.append_on_reconnect) {
    w->FinishLog();
    w->source->ResetClock();
  }
  return true;
}

void Loop(Watch* w) {
  const WatchCommandOptions& o = w->o;
  WatchCommandResult* result = w->result;
  const std::atomic<bool>& interrupt = ProcessInterruptFlag();
  Clock::time_point last_data = Clock::now();
  bool idle_said = false;
  while (true) {
    if (interrupt.load() || (o.keep_going && !o.keep_going())) {
      result->interrupted = interrupt.load();
      result->end_reason = result->interrupted ? "interrupted (Ctrl-C)" : "stopped";
      return;
    }
    std::vector<WatchSample> samples;
    std::vector<RejectedLine> rejected;
    std::string why;
    const bool open = w->source->Next(&samples, &rejected, 0.2, &why);
    if (w->source->TakeRestart()) {
      w->Event(w->source->Describe() + " started over (truncated or replaced): " +
               (o.append_on_reconnect ? "appending to the same log"
                                      : "closing the log and starting a new one"));
      if (!o.append_on_reconnect) {
        w->FinishLog();
        w->source->ResetClock();
      }
    }
    if (!samples.empty() || !rejected.empty()) {
      last_data = Clock::now();
      idle_said = false;
    }
    if (!w->Take(samples, rejected)) return;
    if (!open) {
      w->Event(why +
               (w->log ? "; the log " + w->log->path() + " keeps every sample received" : ""));
      if (!w->source->CanReconnect() || !Reconnect(w, Clock::now())) {
        result->end_reason = w->source->CanReconnect() ? result->end_reason : "end of stream";
        return;
      }
      last_data = Clock::now();
      continue;
    }
    const double idle = std::chrono::duration<double>(Clock::now() - last_data).count();
    if (idle > o.idle_warn_s && !idle_said) {
      w->Event("no sample for " + Fmt("%.0f", idle) + " s from " + w->source->Describe() +
               " (the stream stopped?)");
      idle_said = true;
    }
    if (o.idle_end_s > 0 && idle > o.idle_end_s) {
      result->end_reason = "no sample for " + Fmt("%g", o.idle_end_s) + " s";
      return;
    }
  }
}

nlohmann::json ResultJson(const WatchCommandResult& r) {
  nlohmann::json j;
  j["end_reason"] = r.end_reason;
  j["interrupted"] = r.interrupted;
  j["last_update"] = WatchUpdateToJson(r.last_update);
  nlohmann::json counters;
  counters["samples"] = r.counters.samples;
  counters["garbage"] = r.counters.garbage;
  counters["non_finite"] = r.counters.non_finite;
  counters["out_of_range"] = r.counters.out_of_range;
  counters["time_back"] = r.counters.time_back;
  counters["bad_checksum"] = r.counters.bad_checksum;
  counters["restarts"] = r.counters.restarts;
  j["counters"] = counters;
  j["logs"] = nlohmann::json::array();
  for (const WatchLogResult& log : r.logs) {
    nlohmann::json l;
    l["path"] = log.path;
    l["samples"] = log.samples;
    l["rejected"] = log.rejected;
    l["record"] = log.record ? TraceRecordToJson(*log.record, false) : nlohmann::json();
    j["logs"].push_back(l);
  }
  return j;
}

}  // namespace

int WatchCommandResult::ExitCode() const {
  if (interrupted) return kInterruptedExitCode;
  if (logs.empty() || !logs.back().record || !logs.back().record->ok()) return 1;
  return 0;
}

WatchCommandResult RunWatch(const WatchCommandOptions& options) {
  CheckOptions(options);
  WatchCommandResult result;
  // The config as `fit` runs it (rig.calibration applied): RunFit with no log.
  FitCommandOptions fit;
  fit.config_path = options.config_path;
  const CampaignConfig config = RunFit(fit).config;
  WatchInputOptions input;
  input.format = config.imu.format;
  input.counter_rate_hz = options.counter_rate_hz;
  input.counter_column = options.counter_column;
  input.guess_format = options.guess_format ? options.guess_format : GuessFormat;
  WatchCommandOptions o = options;
  std::unique_ptr<WatchServer> server;
  if (options.serve_port >= 0) {
    server = std::make_unique<WatchServer>(options.serve_port);
    WatchServer* page = server.get();
    o.on_update = [page, user = options.on_update](const WatchUpdate& u) {
      page->Publish(u);
      if (user) user(u);
    };
    o.on_event = [page, user = options.on_event](const std::string& text) {
      page->Event(text);
      if (user) user(text);
    };
    if (o.on_event) o.on_event("the live page is at " + server->url());
  }
  if (o.engine.log_name == "watch") {
    o.engine.log_name = options.source == "-" ? "stdin" : options.source;
  }
  Watch w{
      o,       config,           OpenWatchSource(options.source, config, input), nullptr, nullptr,
      &result, options.save_path};
  if (options.handle_interrupt) InstallInterruptHandler();
  try {
    Loop(&w);
  } catch (const UserError&) {
    w.FinishLog();  // the log keeps what came before the stream became unreadable
    throw;
  }
  result.counters = w.source->counters();
  // Ctrl-C ended the watch, not the fit of what it saved (a second Ctrl-C still kills at once).
  if (result.interrupted) ProcessInterruptFlag().store(false);
  w.FinishLog();
  if (result.logs.empty()) w.Event("no sample received: no log saved");
  result.json = ResultJson(result);
  return result;
}

std::string WatchStatusLine(const WatchUpdate& u) {
  const std::string head = Fmt("t %7.1f s  ", u.t_s);
  switch (u.verdict) {
    case WatchVerdict::kWaiting:
      return head + "waiting for release  noise " + Fmt("%.2g", u.rate_noise_rad_per_s) +
             " rad/s  " + Fmt("%.0f", u.rate_hz) + " Hz" +
             (u.earlier_swings_kg_m2.empty()
                  ? ""
                  : Fmt("  (last swing I %.6g kg m^2)", u.earlier_swings_kg_m2.back()));
    default:
      break;
  }
  std::string line = head + "swing " + std::to_string(u.swing) + "  ";
  if (std::isfinite(u.period_s)) {
    line += Fmt("%5.1f cycles  ", u.cycles) + Fmt("A %5.1f deg  ", u.amplitude_deg) +
            Fmt("T %.4f s  ", u.period_s);
  }
  if (std::isfinite(u.inertia_kg_m2)) {
    line += Fmt("I %.6g", u.inertia_kg_m2) + Fmt(" +- %.2g", u.inertia_std_stat_kg_m2) +
            Fmt(" (total %.2g) kg m^2  ", u.inertia_std_total_kg_m2);
  } else if (std::isfinite(u.small_angle_inertia_kg_m2)) {
    line += Fmt("I(small-angle) %.6g kg m^2  ", u.small_angle_inertia_kg_m2);
  }
  std::string verdict = ToString(u.verdict);
  for (char& c : verdict) c = static_cast<char>(c == '_' ? ' ' : std::toupper(c));
  line += verdict;
  if (u.verdict == WatchVerdict::kSwinging && std::isfinite(u.cycles_needed)) {
    line += Fmt(" (~%.0f more cycles)", std::ceil(u.cycles_needed));
  }
  if (!u.repeat_agreement.empty()) line += "  repeat " + u.repeat_agreement;
  return line;
}

}  // namespace bifilar
