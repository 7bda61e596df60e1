// knit-macro design DESIGN.json --check
//   Inverse design of the l and alpha fields (issue 13, docs/design.md). This round: reads and
//   checks the design file (schemas/design.schema.json) and prints the problem. The optimizer
//   is not implemented yet: without --check the command says so and exits with 1.
//   Exit codes: 0 checked, 1 not implemented, 2 bad input. Nothing is written.
// Example:
//   knit-macro design cases/design/uniform_load.json --check
#include <iostream>
#include <memory>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/macro/design_problem.hpp"

namespace {

struct Options {
  std::string file;
  bool check = false;
};

knit::cli::SubcommandRegistrar reg(
    "design", "Inverse design of the stitch-value and knitting-angle fields (--check: validate)",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("design", o->file, "design file (JSON)")->required();
      sub.add_flag("--check", o->check, "read and check the design file, print the problem");
      return [o]() -> int {
        const auto d = knit::macro::load_design(o->file);
        std::cout << "design: " << o->file << "\ncase: " << d.case_file << "\n";
        for (const auto& v : d.variables) {
          std::cout << "variable " << v.name << ": "
                    << (v.field == knit::macro::DesignVariable::Field::kStitchValue
                            ? "stitch_value"
                            : "knitting_angle")
                    << " control values";
          for (int i : v.indices) std::cout << " " << i;
          std::cout << ", initial " << v.initial << ", bounds [" << v.lower << ", " << v.upper
                    << "]\n";
        }
        for (const auto& ob : d.objectives)
          std::cout << "objective " << ob.name << ": weight " << ob.weight << ", "
                    << ob.at_strain.size() << " applied strain(s)\n";
        std::cout << "smoothness weight: " << d.smoothness << "\n";
        if (o->check) return knit::kExitOk;
        std::cerr << "knit-macro design: the optimizer is not implemented yet (issue 13); "
                     "--check validates the design file\n";
        return knit::kExitFailure;
      };
    });

}  // namespace
