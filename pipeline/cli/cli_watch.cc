// `bifilar watch CONFIG SOURCE [--save FILE] [--json] [--target-percent P] [--cycles N]
// [--stop-at-target] [--counter-rate-hz R] [--idle-end S] [--append]`: the moment of inertia live
// while the body swings (pipeline/commands/watch_command.h). One updating terminal line (a
// carriage return, not a scroll) or, with --json, one JSON object per update. At the end, the
// result of `bifilar fit` on the saved log.
// `bifilar watch CONFIG --feed LOG [--speed X]`: replays LOG as CSV on standard output at X times
// its own pace (a feeder for trying watch without hardware: pipe it into `bifilar watch CONFIG -`).
#include <unistd.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "base/text_format.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/commands/watch_command.h"
#include "pipeline/records/results_json.h"
#include "pipeline/watch/watch_source.h"

namespace bifilar {
namespace {

struct WatchCli {
  WatchCommandOptions o;
  bool json = false;
  std::string feed;
  double speed = 1.0;
};

void PrintFinal(const WatchCommandResult& r, bool json) {
  if (json) {
    nlohmann::json j = r.json;
    j["final"] = true;
    std::cout << j.dump() << "\n";
    return;
  }
  std::cerr << "\n";
  std::cout << "watch ended: " << r.end_reason << "\n";
  if (!r.counters.Text().empty()) std::cout << "input: " << r.counters.Text() << "\n";
  for (const WatchLogResult& log : r.logs) {
    std::cout << log.path << ": " << log.samples << " samples saved";
    if (log.rejected > 0)
      std::cout << ", " << log.rejected << " lines rejected (" << log.path << ".rejected.txt)";
    std::cout << "\n";
    if (!log.record) continue;
    const TraceRecord& t = *log.record;
    std::cout << "  fit: " << ToString(t.status);
    if (std::isfinite(t.inertia_total_kg_m2)) {
      std::cout << Fmt("  I = %.9g", t.inertia_total_kg_m2)
                << Fmt(" +- %.3g", t.inertia_total_std_kg_m2)
                << Fmt(" (total %.3g) kg m^2", t.inertia_total_std_total_kg_m2);
    }
    if (!t.message.empty()) std::cout << "  " << WarningSummary(t.message, 160);
    std::cout << "\n  (the same as `bifilar fit " << r.config_path_for_print << " " << log.path
              << "`)\n";
  }
}

}  // namespace

void RegisterWatchCommand(CLI::App& app, int* exit_code) {
  auto cli = std::make_shared<WatchCli>();
  auto* sub = app.add_subcommand(
      "watch",
      "Watch the moment of inertia converge while the body swings: reads IMU samples from a log "
      "being written, standard input (CSV or JSON lines), a serial port, a WebSocket or MAVLink, "
      "saves every sample, and says `enough`, `swing again` or `fix the rig`");
  sub->add_option("config", cli->o.config_path, "config (YAML), as for `bifilar fit`")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("source", cli->o.source,
                  "a log file being written (CSV, ULog, DataFlash), - for standard input, "
                  "serial:DEV@BAUD, ws://HOST:PORT/PATH, mavlink:DEV@BAUD, mavlink-udp:HOST:PORT");
  sub->add_option("--save", cli->o.save_path,
                  "write every sample to this new CSV (default: watch_<UTC time>.csv beside the "
                  "config; never over an existing file)");
  sub->add_flag("--json", cli->json, "one JSON object per update, and the final result");
  sub->add_option("--target-percent", cli->o.engine.target_percent,
                  "target of the per-swing std of I (% of I), default 0.5")
      ->check(FiniteNumber());
  sub->add_option("--cycles", cli->o.stop_after_cycles, "end once the fit holds N cycles");
  sub->add_flag("--stop-at-target", cli->o.stop_at_target, "end at the first `enough`");
  sub->add_option("--counter-rate-hz", cli->o.counter_rate_hz,
                  "the stream has a sample counter, not a time: its rate (Hz)")
      ->check(FiniteNumber());
  sub->add_option("--counter-column", cli->o.counter_column,
                  "the counter's column or key (default count)");
  sub->add_option("--idle-end", cli->o.idle_end_s,
                  "end when no sample came for this many seconds (default: keep waiting)")
      ->check(FiniteNumber());
  sub->add_flag(
      "--append", cli->o.append_on_reconnect,
      "after a disconnect or a restarted file, append to the same log (default: a new log)");
  sub->add_option("--serve", cli->o.serve_port,
                  "serve the live page on http://127.0.0.1:PORT/ (0: any free port)")
      ->check(CLI::Range(0, 65535));
  sub->add_option("--feed", cli->feed, "replay this log as CSV on standard output (a feeder)");
  sub->add_option("--speed", cli->speed, "--feed: times real time (default 1; 0: at once)")
      ->check(FiniteNumber());
  sub->callback([cli, exit_code] {
    if (!cli->feed.empty()) {
      FitCommandOptions fit;
      fit.config_path = cli->o.config_path;
      ReplayLog(cli->feed, RunFit(fit).config, cli->speed, STDOUT_FILENO);
      *exit_code = 0;
      return;
    }
    if (cli->o.source.empty())
      throw UserError("watch: give a source (a log file, - for stdin, ...)");
    const bool json = cli->json;
    const bool tty = ::isatty(STDERR_FILENO) != 0;
    cli->o.handle_interrupt = true;
    cli->o.on_update = [json, tty](const WatchUpdate& u) {
      if (json) {
        std::cout << WatchUpdateToJson(u).dump() << std::endl;
        return;
      }
      // One line rewritten in place on a terminal; one line per update otherwise (a log file).
      std::cerr << (tty ? "\r\033[K" : "") << WatchStatusLine(u) << (tty ? "" : "\n") << std::flush;
    };
    cli->o.on_event = [json, tty](const std::string& text) {
      if (json) {
        std::cout << nlohmann::json{{"event", text}}.dump() << std::endl;
      } else {
        std::cerr << (tty ? "\r\033[K" : "") << "watch: " << text << "\n";
      }
    };
    WatchCommandResult r = RunWatch(cli->o);
    r.config_path_for_print = cli->o.config_path;
    PrintFinal(r, json);
    *exit_code = r.ExitCode();
  });
}

}  // namespace bifilar
