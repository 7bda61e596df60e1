// knit-meso: the offline, mesoscale half of knitscale (paper Sect. 2.1.2).
//   knit-meso --help        lists the subcommands
//   knit-meso --version     project version and git revision
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{"knit-meso: yarn-level (mesoscale) simulation of single-jersey stitches and the\n"
               "material database of homogenized response surfaces (units: mm, N, MPa)."};
  app.set_version_flag("--version", std::string("knit-meso ") + knit::project_version() + " (git " +
                                        knit::git_revision() + ")");
  app.require_subcommand(1);
  // Subcommands register here as they land (see mesoscale/src/cmd_*.cpp).
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return knit::kExitBadInput;
  } catch (const knit::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return knit::kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return knit::kExitFailure;
  }
  return knit::kExitOk;
}
