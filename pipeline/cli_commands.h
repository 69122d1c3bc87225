// Internal to the CLI: each subcommand lives in its own cli_<name>.cc and registers itself here.
// A command's callback stores its exit code in *exit_code; user errors may throw
// bifilar::UserError, which the dispatcher prints as one line and turns into exit code 2.
#pragma once

#include <CLI/CLI.hpp>

#include "pipeline/user_error.h"

namespace bifilar {

void RegisterSimulateCommand(CLI::App& app, int* exit_code);
void RegisterFitCommand(CLI::App& app, int* exit_code);
void RegisterEllipseCommands(CLI::App& app, int* exit_code);  // `ellipse` and `plan`
void RegisterProcessCommands(CLI::App& app, int* exit_code);  // `process` and `report`
void RegisterInspectCommands(CLI::App& app, int* exit_code);  // `inspect` and `init`

}  // namespace bifilar
