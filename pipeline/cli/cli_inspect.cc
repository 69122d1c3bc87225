// `bifilar inspect LOG... [--config CFG] [--json]`: a look at logs before fitting them
// (pipeline/commands/log_inspect.h). `bifilar init [PATH] [--log FILE] [--rig L,D,MASS] [--force]`:
// a commented starting config (pipeline/config/config_template.h).
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "base/units.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/inspect_command.h"
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
    // Deliberately not base/csv.h's whole-field ParseNumber: an answer at a prompt may carry its
    // unit ("0.5 m"), so the number it starts with is read.
    char* end = nullptr;
    const double value = std::strtod(line.c_str(), &end);
    if (end != line.c_str() && std::isfinite(value) && value > 0) return value;
    std::cout << "  a positive number, please\n";
  }
}

void RegisterInspectCommand(CLI::App& app, int* exit_code) {
  struct Args {
    InspectCommandOptions options;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand(
      "inspect",
      "Look at logs before fitting: format, columns or ULog topics, sample rate, the swing's "
      "window, axis, amplitude and period (and with --config the small-angle inertia)");
  sub->add_option("logs", args->options.logs, "logs: CSV (.csv, .csv.gz) or PX4 ULog (.ulg)")
      ->required();
  sub->add_option("--config", args->options.config_path,
                  "config (YAML) giving the log format and the rig; without it the time and gyro "
                  "columns and units are guessed, and the guesses printed");
  sub->add_flag("--json", args->json, "print a JSON array of reports instead of text");
  sub->callback([args, exit_code] {
    InspectCommandOptions options = args->options;
    if (!args->json) {
      options.on_report = [](const InspectReport& report) {
        std::cout << InspectReportText(report) << std::flush;
      };
    }
    const InspectCommandResult result = RunInspect(options);
    if (args->json) {
      std::cout << result.json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                << std::endl;
    }
    *exit_code = result.ExitCode();
  });
}

// "--gyro X,Y,Z": three column names.
std::array<std::string, 3> GyroColumnsFromFlag(const std::string& text) {
  std::vector<std::string> names;
  std::string cell;
  for (char c : text + ",") {
    if (c != ',') {
      cell += c;
      continue;
    }
    const size_t b = cell.find_first_not_of(" \t"), e = cell.find_last_not_of(" \t");
    names.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
    cell.clear();
  }
  if (names.size() != 3 || names[0].empty() || names[1].empty() || names[2].empty()) {
    throw UserError("init: --gyro takes three column names X,Y,Z (the IMU's x, y, z axes), got '" +
                    text + "'");
  }
  return {names[0], names[1], names[2]};
}

void RegisterInitCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<InitCommandOptions>();
  auto* sub = app.add_subcommand("init", "Write a commented starting config for your rig");
  sub->add_option("path", args->path, "config file to write (default bifilar.yaml)");
  sub->add_option("--log", args->log,
                  "a log of the rig: its format (columns, units or ULog topic) is filled in as "
                  "`bifilar inspect` guesses it");
  sub->add_option("--rig", args->rig,
                  "L,D,MASS: wire length (m), wire separation (m), suspended mass (kg); asked on "
                  "a terminal when not given");
  auto gyro = std::make_shared<std::string>();
  sub->add_option("--time", args->columns.time,
                  "with --log: the log's time column, when the guess misses it (its unit is "
                  "still guessed from the steps)");
  sub->add_option("--gyro", *gyro,
                  "with --log: the log's gyro columns X,Y,Z (IMU axes), when the guess misses "
                  "them (their unit is still guessed from the readings)");
  char gravity_help[160];
  std::snprintf(gravity_help, sizeof(gravity_help),
                "local gravity (m/s^2) in [%g, %g], the range a config accepts; default %g",
                kMinEarthGravityMps2, kMaxEarthGravityMps2, kStandardGravityMps2);
  sub->add_option("--gravity", args->gravity_mps2, gravity_help)->check(FiniteNumber());
  sub->add_flag("--force", args->force, "overwrite PATH if it exists");
  sub->callback([args, gyro, exit_code] {
    InitCommandOptions options = *args;
    if (!gyro->empty()) options.columns.gyro = GyroColumnsFromFlag(*gyro);
    options.ask_rig = [](StartingConfigOptions* rig) {
      if (!isatty(STDIN_FILENO)) return false;
      std::cout << "The rig (SI units; see configs/README.md):\n";
      rig->filar_length_m = AskNumber("  wire length L, pivot to rig (m): ");
      rig->filar_separation_m = AskNumber("  wire separation D (m): ");
      rig->mass_kg = AskNumber("  everything that hangs, rig + aircraft (kg): ");
      return true;
    };
    options.on_guess = [](const std::string& g) { std::cout << "guessed: " << g << "\n"; };
    const std::string path = RunInit(options);
    std::cout << "wrote " << path << "; next: bifilar fit " << path << " LOG\n";
    *exit_code = 0;
  });
}

}  // namespace

void RegisterInspectCommands(CLI::App& app, int* exit_code) {
  RegisterInspectCommand(app, exit_code);
  RegisterInitCommand(app, exit_code);
}

}  // namespace bifilar
