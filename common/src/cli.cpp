#include "knit/core/cli.hpp"

#include <exception>
#include <iostream>
#include <memory>
#include <vector>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"

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

SubcommandRegistrar::SubcommandRegistrar(std::string name, std::string description, Setup setup) {
  registry().push_back({std::move(name), std::move(description), std::move(setup)});
}

int run_main(int argc, char** argv, const std::string& program, const std::string& description) {
  CLI::App app{description, program};
  app.set_version_flag("--version",
                       program + " " + project_version() + " (git " + git_revision() + ")");
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, Runner>> subs;
  for (auto& e : registry()) {
    CLI::App* sub = app.add_subcommand(e.name, e.description);
    subs.emplace_back(sub, e.setup(*sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  try {
    for (auto& [sub, run] : subs)
      if (sub->parsed()) return run();
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitFailure;
}

}  // namespace knit::cli
