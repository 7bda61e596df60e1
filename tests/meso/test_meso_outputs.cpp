// knit-meso's outputs (issue 14, docs/io.md "Output targets"): every command checks its output
// before any work (exit 2, naming the option and the path) and locks it against a concurrent
// run; `path` and `cell` build their directory atomically (a killed run leaves the previous
// output as it was), and stale partial directories of killed runs are cleaned -- only ours.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "../output_test_util.hpp"
#include "test_sweep_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kExe = std::string(KNIT_BIN_DIR) + "/knit-meso";

knit_test::CommandResult meso(const std::string& args) {
  return knit_test::run_command(kExe + " " + args);
}

}  // namespace

TEST_CASE("knit-meso: every command refuses an output it cannot write before any work",
          "[unit][outputs]") {
  const fs::path d = knit_test::scratch("meso_outputs_targets");
  knit_test::write_text(d / "s.json", knit_test::synthetic_sweep_json());
  std::ofstream(d / "file") << "a file";
  fs::create_directories(d / "dir");
  std::ofstream(d / "dir" / "keep.txt") << "precious";
  fs::create_symlink(d / "missing", d / "dangling");
  const std::string file = (d / "file").string(), dir = (d / "dir").string(),
                    dangling = (d / "dangling").string(), under_file = file + "/sub";
  const std::string rod_case = std::string(KNIT_SOURCE_DIR) + "/cases/rod/elastica.json";
  const std::string count = (d / "count.txt").string();
  // Directory outputs.
  for (const std::string& t :
       {file, dangling, under_file, dir, std::string(".."), std::string("/")}) {
    for (const std::string& cmd :
         {std::string("cell --loop-length 4.5 --out "),
          std::string("path --loop-length 4.5 --shear 10 --steps 1 --out "),
          "rod " + rod_case + " --output "}) {
      INFO(cmd << t);
      const auto r =
          knit_test::run_command("cd " + d.string() + " && " + kExe + " " + cmd + "\"" + t + "\"");
      CHECK(r.rc == 2);
      CHECK((knit_test::contains(r.output, "--out") || knit_test::contains(r.output, "--output")));
      CHECK(!knit_test::contains(r.output, "step "));
    }
  }
  // File outputs: the sweep is checked before its cases run (the count file stays absent).
  for (const std::string& t : {dir, dangling, under_file + "/db.h5", std::string("..")}) {
    INFO("sweep --output " << t);
    const auto r = knit_test::run_command(
        "cd " + d.string() + " && KNIT_SWEEP_TEST_COUNT_FILE=" + count + " " + kExe + " sweep " +
        (d / "s.json").string() + " --output \"" + t + "\"");
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "--output"));
    CHECK(!fs::exists(count));
    const auto synth = meso("synth --out \"" + t + "\"");
    CHECK(synth.rc == 2);
    CHECK(knit_test::contains(synth.output, "--out"));
    std::ofstream(d / "db.h5") << "the input database";
    const auto fit = meso("fit " + (d / "db.h5").string() + " --out \"" + t + "\"");
    CHECK(fit.rc == 2);
    CHECK(knit_test::contains(fit.output, "--out"));
  }
  CHECK(fs::is_regular_file(d / "file"));
  CHECK(fs::exists(d / "dir" / "keep.txt"));
  fs::remove_all(d);
}

TEST_CASE("knit-meso: an output in use by another run is refused, naming its pid",
          "[unit][outputs]") {
  const fs::path d = knit_test::scratch("meso_outputs_lock");
  {
    knit_test::LockHolder other(d / "cell.lock");
    REQUIRE(other.pid() > 0);
    const auto r = meso("cell --loop-length 4.5 --out " + (d / "cell").string());
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "pid " + std::to_string(other.pid())));
    CHECK(!fs::exists(d / "cell"));
    other.release();
    CHECK(meso("cell --loop-length 4.5 --out " + (d / "cell").string()).rc == 0);
    CHECK(fs::exists(d / "cell" / "cell.json"));
  }
  {  // Two sweeps of the same database: the second must not touch the first's checkpoints.
    knit_test::write_text(d / "s.json", knit_test::synthetic_sweep_json());
    fs::create_directories(d / "db.h5.parts");
    knit_test::write_text(d / "db.h5.parts" / "manifest.json", "{}");
    knit_test::LockHolder other(d / "db.h5.lock");
    for (const char* flag : {" --force", " --resume"}) {
      const auto r =
          meso("sweep " + (d / "s.json").string() + " --output " + (d / "db.h5").string() + flag);
      CHECK(r.rc == 2);
      CHECK(knit_test::contains(r.output, "pid " + std::to_string(other.pid())));
      CHECK(fs::exists(d / "db.h5.parts" / "manifest.json"));
    }
  }
  {  // A file named like a lock that is not ours is neither used nor changed.
    knit_test::write_text(d / "x.lock", "not a lock");
    const auto r = meso("cell --loop-length 4.5 --out " + (d / "x").string());
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "not a knitscale lock file"));
    CHECK(knit_test::read_text(d / "x.lock") == "not a lock");
  }
  fs::remove_all(d);
}

TEST_CASE("knit-meso path: a killed run leaves the previous output as it was", "[unit][outputs]") {
  const fs::path d = knit_test::scratch("meso_outputs_atomic");
  const fs::path out = d / "p";
  REQUIRE(
      meso("path --loop-length 4.5 --shear 10 --steps 2 --elements 16 --out " + out.string()).rc ==
      0);
  const std::string csv = knit_test::read_text(out / "path.csv");
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const int fd = ::open("/dev/null", O_WRONLY);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(kExe.c_str(), kExe.c_str(), "path", "--loop-length", "4.5", "--shear", "20", "--steps",
            "200", "--elements", "16", "--out", out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Kill it once it has written its fourth step (into its partial directory, or before the
  // fix into the output itself).
  fs::path partial = out;
  partial += ".partial-" + std::to_string(pid);
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(partial / "yarn_0003.vtp") && !fs::exists(out / "yarn_0003.vtp") &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  CHECK(!fs::exists(out / "yarn_0003.vtp"));  // nothing of the killed run in the output
  CHECK(knit_test::read_text(out / "path.csv") == csv);
  CHECK(fs::exists(partial));  // the stale partial directory of the killed run ...
  // ... is cleaned by the next run into the same output; a stale-looking directory without
  // the marker, or of a live process, is not ours (or not stale) and stays.
  fs::path foreign = out, live = out;
  foreign += ".partial-" + std::to_string(knit_test::dead_pid());
  live += ".partial-1";
  fs::create_directories(foreign);
  fs::create_directories(live);
  std::ofstream(live / ".knitscale-output") << "knitscale output\n";
  REQUIRE(meso("path --loop-length 4.5 --shear 10 --steps 1 --elements 16 --no-vtp --out " +
               out.string())
              .rc == 0);
  CHECK(!fs::exists(partial));
  CHECK(fs::exists(foreign));
  CHECK(fs::exists(live));
  fs::remove_all(d);
}

// Session 34: a full disk or a failing fsync, made by a shim preloaded into knit-meso
// (tests/support/fail_io_shim.c), on the database (a single file, written atomically) and on a
// path's directory: exit 1, the earlier output unchanged, nothing left beside it, and the
// system's reason in the message (a database that could not be created said "directory
// missing or not writable?" on a full disk).
TEST_CASE("knit-meso: a write or fsync that fails leaves the earlier database and path output",
          "[unit][outputs]") {
  const fs::path d = knit_test::scratch("meso_outputs_fail_io");
  const auto failing = [&](const std::string& env, const std::string& args) {
    return knit_test::run_command(knit_test::with_fail_io_shim(env) + kExe + " " + args);
  };
  const auto nothing_beside = [&](const std::string& name) {
    for (const auto& e : fs::directory_iterator(d)) {
      const std::string f = e.path().filename().string();
      INFO(f);
      CHECK((f == name || f.rfind(name + ".", 0) != 0));
      CHECK(f.rfind("." + name + ".tmp", 0) != 0);
    }
  };
  const fs::path db = d / "db.h5";
  const std::string synth = "synth --no-coverage --loop-lengths 4.5,6.5 --out " + db.string();
  REQUIRE(failing("", synth).rc == 0);  // the shim changes nothing unless asked
  const std::string before = knit_test::read_text(db);
  for (const std::string env : {"KNIT_FAIL_WRITE=.db.h5.tmp", "KNIT_FAIL_FSYNC=.db.h5.tmp"}) {
    const auto r = failing(env, synth);
    INFO(env << ": " << r.output);
    CHECK(r.rc == 1);
    CHECK(r.output.find("database not written (the earlier file is left as it was)") !=
          std::string::npos);
    CHECK((r.output.find("No space left on device") != std::string::npos ||
           r.output.find("Input/output error") != std::string::npos));
    CHECK(knit_test::read_text(db) == before);
    nothing_beside("db.h5");
  }
  // The lock file cannot be created: a full disk is no bad input (it was exit 2).
  {
    const auto r = failing("KNIT_FAIL_WRITE=db.h5.lock", synth);
    INFO(r.output);
    CHECK(r.rc == 1);
    CHECK(r.output.find("cannot create the lock file") != std::string::npos);
    CHECK(r.output.find("No space left on device") != std::string::npos);
    CHECK(knit_test::read_text(db) == before);
    nothing_beside("db.h5");
  }
  const fs::path out = d / "p";
  const std::string path =
      "path --loop-length 4.5 --shear 10 --steps 2 --elements 16 --out " + out.string();
  REQUIRE(meso(path).rc == 0);
  const std::string csv = knit_test::read_text(out / "path.csv");
  for (const std::string env : {"KNIT_FAIL_WRITE=path.csv", "KNIT_FAIL_FSYNC=path.csv",
                                "KNIT_FAIL_WRITE=yarn_0001.vtp", "KNIT_FAIL_FSYNC=yarn_0002.vtp"}) {
    const auto r = failing(env, path);
    INFO(env << ": " << r.output);
    CHECK(r.rc == 1);
    CHECK(r.output.find("outputs not written (the earlier outputs are left as they were)") !=
          std::string::npos);
    CHECK(knit_test::read_text(out / "path.csv") == csv);
    nothing_beside("p");
  }
}
