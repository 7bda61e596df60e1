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
//
// Every numeric option carries a range validator (number() / integer() below) so that a
// non-finite or out-of-range value is refused at parse time, before any work, with a message
// naming the option and the allowed range (CLI11's own CLI::Range lets NaN through):
//   sub.add_option("--mu", o->mu, "...")->check(knit::cli::number(0, 10));
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <string_view>

namespace knit::cli {

using Runner = std::function<int()>;
using Setup = std::function<Runner(CLI::App&)>;

struct SubcommandRegistrar {
  SubcommandRegistrar(std::string name, std::string description, Setup setup);
};

/// Which ends of a range are open (excluded).
enum class Ends { kClosed, kOpenLow, kOpenHigh, kOpen };

/// A validator for a floating-point option: the value must parse completely as a finite
/// decimal number (no hex, no blanks) within [lo, hi] (ends excluded as `ends` says). Use
/// +-infinity for no bound.
CLI::Validator number(double lo, double hi, Ends ends = Ends::kClosed);

/// A validator for an integer option: an integer within [lo, hi].
CLI::Validator integer(long long lo, long long hi);
/// Refuses an empty value; run_main puts it on every option that takes a value.
CLI::Validator non_empty();

/// The text "[lo, hi]" / "(lo, hi]" / "> lo" ... of a range, for messages and help.
std::string describe_range(double lo, double hi, Ends ends);

/// `arg` as one word of a POSIX shell command, for a command a message tells the user to run:
/// unchanged when it holds only letters, digits and @%+=:,./_- (and is not empty), otherwise
/// in single quotes, a ' inside as '\'' (session 44's red team: the sweep's resume command for
/// "my input.json" failed when pasted).
std::string shell_quote(std::string_view arg);

/// Builds the app from the registered subcommands, parses, runs; returns the exit code.
int run_main(int argc, char** argv, const std::string& program, const std::string& description);

/// The line printed on stderr when SIGINT, SIGTERM or SIGHUP ends the process (it then ends
/// as the signal would). run_main sets a general one before the subcommand runs ("<program>
/// <subcommand>: interrupted; ..."); a subcommand that knows more (the sweep: its checkpoints
/// and the --resume command) replaces it. Async-signal-safe: the line is copied (up to 4 kB)
/// here, and the handler only write()s it.
void on_interrupt_say(const std::string& line);

}  // namespace knit::cli
