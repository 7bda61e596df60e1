// schemas/case.schema.json accepts every case file in cases/ and rejects what the loader
// rejects (active once knit/io's schema validator is available).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "knit/io/json_input.hpp"
#include "verification_case.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

TEST_CASE("every macroscale case file validates against the case schema", "[unit]") {
  const auto& schema = knit::io::JsonSchema::embedded("case");
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(KNIT_SOURCE_DIR) / "cases")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    const json j = json::parse(in);
    if (!j.contains("geometry") || !j.contains("material")) continue;  // not a shell case
    const auto errors = schema.errors(j);
    INFO(e.path().string() << (errors.empty()
                                   ? ""
                                   : ": " + errors[0].pointer + ": " + errors[0].message));
    CHECK(errors.empty());
    ++n;
  }
  CHECK(n >= 4);
}

TEST_CASE("the case schema rejects unknown keys, bad edges and points outside [0,1]^2", "[unit]") {
  const auto& schema = knit::io::JsonSchema::embedded("case");
  const json base = knit::macro::test::verification_case("tensile_svk.json");
  json a = base;
  a["solver"]["stepz"] = 1;
  CHECK(!schema.errors(a).empty());
  json b = base;
  b["boundary_conditions"][0]["edge"] = "u2";
  CHECK(!schema.errors(b).empty());
  json c = base;
  c["output"]["points"][0]["at"] = {0.5, 1.5};
  CHECK(!schema.errors(c).empty());
  json d = base;
  d["geometry"]["thickness"] = -1;
  CHECK(!schema.errors(d).empty());
  json e = base;
  e["material"]["type"] = "rubber";
  CHECK(!schema.errors(e).empty());
}
