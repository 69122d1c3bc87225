#include <iostream>

#include "pipeline/cli_commands.h"

namespace bifilar {

// Placeholder until the command lands.
void RegisterProcessCommands(CLI::App& app, int* exit_code) {
  auto* sub = app.add_subcommand("process", "(not implemented yet)");
  sub->callback([exit_code] {
    std::cerr << "bifilar: error: 'process' is not implemented yet\n";
    *exit_code = 2;
  });
}

}  // namespace bifilar
