// `bifilar inspect LOG... [--config CFG] [--json]`: a look at logs before fitting them
// (pipeline/commands/log_inspect.h). `bifilar init [PATH] [--log FILE] [--rig L,D,MASS] [--force]`:
// a commented starting config (pipeline/config/config_template.h).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "base/atomic_file.h"
#include "base/units.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/config/config.h"
#include "pipeline/config/config_template.h"

namespace bifilar {
namespace {

// Asks for one positive number on the terminal; throws UserError at end of input.
double AskNumber(const std::string& question) {
  while (true) {
    std::cout << question << std::flush;
    std::string line;
    if (!std::getline(std::cin, line)) throw UserError("init: no answer to \"" + question + "\"");
    char* end = nullptr;
    const double value = std::strtod(line.c_str(), &end);
    if (end != line.c_str() && std::isfinite(value) && value > 0) return value;
    std::cout << "  a positive number, please\n";
  }
}

void RegisterInspectCommand(CLI::App& app, int* exit_code) {
  struct Args {
    std::vector<std::string> logs;
    std::string config;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand(
      "inspect",
      "Look at logs before fitting: format, columns or ULog topics, sample rate, the swing's "
      "window, axis, amplitude and period (and with --config the small-angle inertia)");
  sub->add_option("logs", args->logs, "logs: CSV (.csv, .csv.gz) or PX4 ULog (.ulg)")->required();
  sub->add_option("--config", args->config,
                  "config (YAML) giving the log format and the rig; without it the time and gyro "
                  "columns and units are guessed, and the guesses printed");
  sub->add_flag("--json", args->json, "print a JSON array of reports instead of text");
  sub->callback([args, exit_code] {
    std::optional<CampaignConfig> config;
    if (!args->config.empty()) {
      ConfigLoadOptions load;
      load.require_runs = false;
      config = LoadCampaignConfig(args->config, load);
    }
    nlohmann::json all = nlohmann::json::array();
    int bad = 0;
    for (const std::string& log : args->logs) {
      const InspectReport report = InspectLog(log, config ? &*config : nullptr);
      if (!report.is_log() || !report.error.empty()) ++bad;
      if (args->json) {
        all.push_back(InspectReportToJson(report));
      } else {
        std::cout << InspectReportText(report) << std::flush;
      }
    }
    if (args->json) {
      std::cout << all.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
    }
    *exit_code = bad > 0 ? 1 : 0;
  });
}

void RegisterInitCommand(CLI::App& app, int* exit_code) {
  struct Args {
    std::string path = "bifilar.yaml";
    std::string log, rig;
    double gravity_mps2 = kStandardGravityMps2;
    bool force = false;
  };
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand("init", "Write a commented starting config for your rig");
  sub->add_option("path", args->path, "config file to write (default bifilar.yaml)");
  sub->add_option("--log", args->log,
                  "a log of the rig: its format (columns, units or ULog topic) is filled in as "
                  "`bifilar inspect` guesses it");
  sub->add_option("--rig", args->rig,
                  "L,D,MASS: wire length (m), wire separation (m), suspended mass (kg); asked on "
                  "a terminal when not given");
  char gravity_help[160];
  std::snprintf(gravity_help, sizeof(gravity_help),
                "local gravity (m/s^2) in [%g, %g], the range a config accepts; default 9.80665",
                kMinEarthGravityMps2, kMaxEarthGravityMps2);
  sub->add_option("--gravity", args->gravity_mps2, gravity_help)->check(FiniteNumber());
  sub->add_flag("--force", args->force, "overwrite PATH if it exists");
  sub->callback([args, exit_code] {
    RefuseToReplace(args->path, "init", args->force);  // base/atomic_file.h
    StartingConfigOptions options;
    options.gravity_mps2 = args->gravity_mps2;
    {
      std::string why;  // the config's own bound and message (pipeline/config/config.h)
      if (!CheckGravity(args->gravity_mps2, false, &why)) throw UserError("init: --gravity: " + why);
    }
    if (!args->rig.empty()) {
      std::string why;
      if (!ParseRigSpec(args->rig, &options, &why)) throw UserError(why);
    } else if (isatty(STDIN_FILENO)) {
      std::cout << "The rig (SI units; see configs/README.md):\n";
      options.filar_length_m = AskNumber("  wire length L, pivot to rig (m): ");
      options.filar_separation_m = AskNumber("  wire separation D (m): ");
      options.mass_kg = AskNumber("  everything that hangs, rig + aircraft (kg): ");
      std::string why;
      if (!options.Check(&why)) throw UserError("init: " + why);
    } else {
      throw UserError("init: give the rig with --rig L,D,MASS (m, m, kg), e.g. --rig "
                      "0.594,0.030,0.0343, or run it on a terminal to be asked");
    }
    if (!args->log.empty()) {
      const InspectReport report = InspectLog(args->log, nullptr);
      if (!report.is_log()) {
        throw UserError("init: --log " + (report.error.empty() ? args->log : report.error));
      }
      options.format = report.format;
      options.ulog = report.kind == "ulog";
      options.format_source = args->log;
      for (const std::string& g : report.guesses) std::cout << "guessed: " << g << "\n";
    }
    WriteFileAtomically(args->path, CheckedStartingConfigText(options, args->path));
    std::cout << "wrote " << args->path << "; next: bifilar fit " << args->path << " LOG\n";
    *exit_code = 0;
  });
}

}  // namespace

void RegisterInspectCommands(CLI::App& app, int* exit_code) {
  RegisterInspectCommand(app, exit_code);
  RegisterInitCommand(app, exit_code);
}

}  // namespace bifilar
