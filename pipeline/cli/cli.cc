#include "pipeline/cli/cli.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <iostream>
#include <string>

#include "base/json_error.h"
#include "base/version.h"
#include "fit/solver_logging.h"
#include "pipeline/cli/cli_commands.h"

#include <nlohmann/json.hpp>

namespace bifilar {
namespace {

// The command and the files it was given ("bifilar ellipse on table.csv"), for a message that
// has no other context (an allocation failing outside any per-file handler).
std::string CommandAndInputs(int argc, char** argv) {
  std::string command = "bifilar";
  std::string files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    std::error_code ec;
    if (i == 1 && arg.rfind("-", 0) != 0) {
      command += " " + arg;
    } else if (std::filesystem::is_regular_file(arg, ec)) {
      files += (files.empty() ? "" : ", ") + arg;
    }
  }
  return command + (files.empty() ? std::string() : " on " + files);
}

}  // namespace

CLI::Validator FiniteNumber() {
  return CLI::Validator(
      [](std::string& input) {
        // strtod, not stod: stod throws on underflow too, which called 1e-308 (a subnormal
        // number) "not a number". A value beyond the double range is out of range.
        char* end = nullptr;
        errno = 0;
        const double value = std::strtod(input.c_str(), &end);
        if (input.empty() || end != input.c_str() + input.size()) {
          return "'" + input + "' is not a number";
        }
        if (errno == ERANGE && std::fabs(value) > 1.0) {
          return "'" + input + "' is out of range (a finite number within +-1.8e308)";
        }
        if (!std::isfinite(value)) return "'" + input + "' is not a finite number";
        return std::string();
      },
      "NUMBER", "finite number");
}

uint64_t ParseSeed(const std::string& text, const std::string& flag, uint64_t max) {
  const std::string range = "[0, " + std::to_string(max) + "]";
  bool digits = !text.empty() && text.size() <= 20;
  for (char c : text) digits = digits && c >= '0' && c <= '9';
  uint64_t value = 0;
  if (digits) {
    errno = 0;
    const unsigned long long parsed = std::strtoull(text.c_str(), nullptr, 10);
    digits = errno == 0 && parsed <= max;
    value = parsed;
  }
  if (!digits) {
    throw UserError(flag + " '" + text.substr(0, 40) + "': a seed is an integer in " + range);
  }
  return value;
}

int RunCommandLine(int argc, char** argv) {
  QuietSolverLogging();  // fit/solver_logging.h: no glog preamble or solver chatter
  CLI::App app{"bifilar: aircraft mass properties from bifilar pendulum IMU logs"};
  app.set_version_flag("--version", std::string("bifilar ") + ProgramVersion());
  app.require_subcommand(1);
  int exit_code = 0;
  RegisterProcessCommands(app, &exit_code);
  RegisterFitCommand(app, &exit_code);
  RegisterEllipseCommands(app, &exit_code);
  RegisterSimulateCommand(app, &exit_code);
  RegisterInspectCommands(app, &exit_code);
  RegisterExportCommand(app, &exit_code);
  RegisterWatchCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print as CLI11 does; a usage error gets the prefix every other
    // error has, so scripts and users can grep one form.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string what = e.what();
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty()) {
      std::string names;  // CLI11 says only "A subcommand is required" for `bifilar fitt`
      for (const CLI::App* sub : app.get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + sub->get_name();
      }
      what = std::string("unknown command '") + argv[1] + "'; the commands are " + names;
    }
    std::cerr << "bifilar: error: " << what << "\nRun with --help for more information.\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "bifilar: error: out of memory in `" << CommandAndInputs(argc, argv)
              << "`: one of these inputs (a file, or a count in the config or options) is far "
                 "larger than this machine can hold; see the limits in configs/README.md\n";
    return 2;
  } catch (const nlohmann::json::exception& e) {  // a path without its own handler
    std::cerr << "bifilar: error: in `" << CommandAndInputs(argc, argv)
              << "`: a JSON value could not be read or written (" << DescribeJsonError(e)
              << "); check the files named, or report this with them\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bifilar: error: " << e.what() << "\n";
    return 2;
  }
  return exit_code;
}

}  // namespace bifilar
