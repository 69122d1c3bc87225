#include <iostream>

#include "pipeline/cli_commands.h"

namespace bifilar {

// Placeholder until the command lands.
void RegisterFitCommand(CLI::App& app, int* exit_code) {
  auto* sub = app.add_subcommand("fit", "(not implemented yet)");
  sub->callback([exit_code] {
    std::cerr << "bifilar: error: 'fit' is not implemented yet\n";
    *exit_code = 2;
  });
}

}  // namespace bifilar
