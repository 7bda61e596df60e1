// Command-line adapter (CLI11 stays behind this header and cli.cpp).
//
// Each subcommand lives in its own file in the executable's sources (mesoscale/src/cmd_*.cpp,
// macroscale/src/cmd_*.cpp) and registers itself with a static SubcommandRegistrar:
//
//   static knit::cli::SubcommandRegistrar reg("rod", "Solve one rod problem from a JSON case",
//     [](CLI::App& sub) {
//       auto opts = std::make_shared<Options>();
//       sub.add_option("case", opts->file, "case file")->required();
//       return [opts]() -> int { ...; return knit::kExitOk; };
//     });
//
// run_main() parses the command line, runs the chosen subcommand and turns errors into exit
// codes: InputError and CLI usage errors -> 2, other exceptions -> 1.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace knit::cli {

using Runner = std::function<int()>;
using Setup = std::function<Runner(CLI::App&)>;

struct SubcommandRegistrar {
  SubcommandRegistrar(std::string name, std::string description, Setup setup);
};

/// Builds the app from the registered subcommands, parses, runs; returns the exit code.
int run_main(int argc, char** argv, const std::string& program, const std::string& description);

}  // namespace knit::cli
