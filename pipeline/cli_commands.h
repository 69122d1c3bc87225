// Internal to the CLI: each subcommand lives in its own cli_<name>.cc and registers itself here.
// A command's callback stores its exit code in *exit_code; user errors may throw
// bifilar::UserError, which the dispatcher prints as one line and turns into exit code 2.
#pragma once

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

namespace bifilar {

// Bad input from a user: the message names the file, line or key and what was expected.
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void RegisterSimulateCommand(CLI::App& app, int* exit_code);
void RegisterFitCommand(CLI::App& app, int* exit_code);
void RegisterEllipseCommands(CLI::App& app, int* exit_code);  // `ellipse` and `plan`
void RegisterProcessCommands(CLI::App& app, int* exit_code);  // `process` and `report`
void RegisterBenchCommand(CLI::App& app, int* exit_code);

}  // namespace bifilar
