// knit-macro: the online, macroscale half of knitscale (paper Sect. 2.1.3, 2.2).
//   knit-macro --help        lists the subcommands
//   knit-macro --version     project version and git revision
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{"knit-macro: fabric-level (macroscale) simulation of graded knitted textiles as\n"
               "nonlinear isogeometric Kirchhoff-Love shells (units: mm, N, MPa)."};
  app.set_version_flag("--version", std::string("knit-macro ") + knit::project_version() + " (git " +
                                        knit::git_revision() + ")");
  app.require_subcommand(1);
  // Subcommands register here as they land (see macroscale/src/cmd_*.cpp).
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
