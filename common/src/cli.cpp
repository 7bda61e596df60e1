#include "knit/core/cli.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <vector>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/names.hpp"

namespace knit::cli {

namespace {
struct Entry {
  std::string name, description;
  Setup setup;
};
std::vector<Entry>& registry() {
  static std::vector<Entry> r;
  return r;
}
}  // namespace

std::string shell_quote(std::string_view arg) {
  const bool plain = !arg.empty() && std::all_of(arg.begin(), arg.end(), [](char ch) {
    const unsigned char u = static_cast<unsigned char>(ch);
    return std::isalnum(u) || std::string_view("@%+=:,./_-").find(ch) != std::string_view::npos;
  });
  if (plain) return std::string(arg);
  std::string q = "'";
  for (const char ch : arg) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

std::string describe_range(double lo, double hi, Ends ends) {
  const bool lo_open = ends == Ends::kOpenLow || ends == Ends::kOpen;
  const bool hi_open = ends == Ends::kOpenHigh || ends == Ends::kOpen;
  std::ostringstream os;
  os.precision(12);
  if (std::isinf(lo) && std::isinf(hi))
    os << "a finite number";
  else if (std::isinf(hi))
    os << (lo_open ? "> " : ">= ") << lo;
  else if (hi >= 1e300 && !hi_open)  // the inputs' "finite" bound (homog_cell_config.cpp)
    os << (lo_open ? "> " : ">= ") << lo << " and finite (at most 1e300)";
  else if (std::isinf(lo))
    os << (hi_open ? "< " : "<= ") << hi;
  else
    os << "in " << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
  return os.str();
}

CLI::Validator number(double lo, double hi, Ends ends) {
  const std::string range = describe_range(lo, hi, ends);
  const bool lo_open = ends == Ends::kOpenLow || ends == Ends::kOpen;
  const bool hi_open = ends == Ends::kOpenHigh || ends == Ends::kOpen;
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        // Decimal only: strtod also reads "0x4" (as 4, session 36's red team) and leading
        // blanks, which the JSON inputs and the integer options refuse.
        const bool decimal = text.find_first_of("xXpP \t\n") == std::string::npos;
        if (text.empty() || end == text.c_str() || *end != '\0' || !decimal)
          return "must be a number " + range + ", got \"" + text + "\"";
        // (session 38's red team: "must be a finite number >= 0 and finite" for --mu nan)
        if (!std::isfinite(v) || errno == ERANGE)
          return (range.find("finite") == std::string::npos ? "must be a finite number "
                                                            : "must be ") +
                 range + ", got " + text;
        if ((lo_open ? !(v > lo) : !(v >= lo)) || (hi_open ? !(v < hi) : !(v <= hi)))
          return "must be " + range + ", got " + text;
        return {};
      },
      "NUMBER " + range);
}

CLI::Validator integer(long long lo, long long hi) {
  const std::string range = describe_range(double(lo), double(hi), Ends::kClosed);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || end == text.c_str() || *end != '\0' || errno == ERANGE)
          return "must be an integer " + range + ", got \"" + text + "\"";
        if (v < lo || v > hi) return "must be an integer " + range + ", got " + text;
        return {};
      },
      "INTEGER " + range);
}

CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return text.empty() ? "must not be empty (leave the option out to take its default)"
                            : std::string();
      },
      "");
}

SubcommandRegistrar::SubcommandRegistrar(std::string name, std::string description, Setup setup) {
  registry().push_back({std::move(name), std::move(description), std::move(setup)});
}

namespace {
// The line an interrupted run prints (SIGINT, SIGTERM, SIGHUP) before it ends by the signal:
// prepared beforehand, written by an async-signal-safe handler (the sweep's since session 21;
// every program's since session 26: run, design and fit ended silently).
char g_interrupt_line[4096];
std::size_t g_interrupt_length = 0;

void on_cli_interrupt(int sig) {
  // The half-written files of this process go first (session 43's red team: an interrupted
  // database write left ".DB.h5.tmp-<pid>-<n>" of up to 800 KB beside the target).
  knit::io::unlink_live_temporaries();
  if (g_interrupt_length > 0) {
    const ssize_t ignored = ::write(STDERR_FILENO, g_interrupt_line, g_interrupt_length);
    (void)ignored;
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}
}  // namespace

void on_interrupt_say(const std::string& line) {
  const std::string m = "\n" + line + "\n";
  g_interrupt_length = 0;  // no half-copied line if a signal comes now
  const std::size_t n = std::min(m.size(), sizeof g_interrupt_line);
  std::memcpy(g_interrupt_line, m.data(), n);
  g_interrupt_length = n;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_cli_interrupt);
}

int run_main(int argc, char** argv, const std::string& program, const std::string& description) {
  CLI::App app{description, program};
  app.set_version_flag("--version",
                       program + " " + project_version() + " (git " + git_revision() + ")");
  app.require_subcommand(1);
  // The exit codes, at the foot of every --help (session 22: they were only in the docs).
  const std::string exit_codes =
      "\nExit codes: 0 done (warnings, if any, on stderr); 1 the computation failed or its "
      "outputs could not be written (the message says what is kept); 2 bad command line or input "
      "(the message names the file and the field). Units: mm, N, MPa.";
  app.footer(exit_codes);
  std::vector<std::pair<CLI::App*, Runner>> subs;
  for (auto& e : registry()) {
    CLI::App* sub = app.add_subcommand(e.name, e.description);
    sub->footer(exit_codes);
    subs.emplace_back(sub, e.setup(*sub));
    // An option given with an empty value is refused (exit 2) instead of being taken as not
    // given: `-o ""` (an unset shell variable) fell back to the default output, and for
    // `knit-meso fit` that default is to replace the input database (session 24).
    for (CLI::Option* opt : sub->get_options())
      if (opt->get_type_size_max() != 0) opt->check(non_empty());
  }
  // Every message names the program it comes from (session 25: a bad option printed CLI11's
  // bare "The following argument was not expected: --force", and an input error "error: ...":
  // in a pipeline's log or under make -j the lines of several programs interleave).
  // "knit-meso fit" when the subcommand was reached, else "knit-meso".
  const auto who = [&] {
    for (const auto& s : subs)
      if (s.first->parsed()) return program + " " + s.first->get_name();
    return program;
  };
  // An unknown first word is named with the subcommands (session 37: CLI11 said only "A
  // subcommand is required" for `knit-macro frobnicate`).
  if (argc >= 2 && argv[1][0] != '-' && std::none_of(subs.begin(), subs.end(), [&](const auto& s) {
        return s.first->check_name(argv[1]);
      })) {
    std::vector<std::string> names;
    for (const auto& s : subs) names.push_back(s.first->get_name());
    std::cerr << program << ": unknown subcommand '" << argv[1]
              << "' (subcommands: " << io::join_names(names) << "); run " << program << " --help\n";
    return kExitBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << who() << ": " << CLI::FailureMessage::simple(&app, e);
    return kExitBadInput;
  }
  // The markers of this run's output directories name it (knit/io/output_target.hpp).
  io::set_output_owner(who());
  // What the interrupt leaves beside an output, and who removes it (session 56's walkthrough:
  // DIR.partial-<pid> and DIR.lock were found after Ctrl-C, unexplained; docs/io.md).
  on_interrupt_say(who() +
                   ": interrupted; outputs not yet complete are not written, earlier outputs "
                   "stay as they were; a left-over OUTPUT.lock and OUTPUT.partial-<pid> beside "
                   "an output are removed by the next run into it");
  try {
    for (auto& [sub, run] : subs)
      if (sub->parsed()) return run();
  } catch (const InputError& e) {
    std::cerr << who() << ": error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    // Out of memory names what ran out and what to do (session 46's red team: a design under a
    // memory limit ended in "error: std::bad_alloc"); earlier outputs stay (atomic writers).
    std::cerr << who()
              << ": error: out of memory (std::bad_alloc); outputs not yet complete are not "
                 "written, earlier outputs stay as they were: make the problem smaller (fewer "
                 "elements, samples or steps) or give the process more memory\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    // An output directory abandoned by the failure is named as itself, not as its partial
    // directory (gone by now), with what became of it (knit/io/atomic.hpp).
    std::cerr << who() << ": error: " << io::explain_unwritten_outputs(e.what()) << "\n";
    return kExitFailure;
  }
  return kExitFailure;
}

}  // namespace knit::cli
