#include <iostream>

#include "pipeline/cli_commands.h"

namespace bifilar {

// Placeholder until the command lands.
void RegisterBenchCommand(CLI::App& app, int* exit_code) {
  auto* sub = app.add_subcommand("bench", "(not implemented yet)");
  sub->callback([exit_code] {
    std::cerr << "bifilar: error: 'bench' is not implemented yet\n";
    *exit_code = 2;
  });
}

}  // namespace bifilar
