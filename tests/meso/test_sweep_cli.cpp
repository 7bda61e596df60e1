// knit-meso sweep as a program (issue #7): exit code 2 on bad input, a sweep killed with
// SIGKILL midway and resumed, and the MPI run with 2 ranks -- all with the synthetic runner
// (instant and deterministic), so that what is tested is the orchestration.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <thread>

#include "knit/meso/sweep/mpi.hpp"
#include "test_sweep_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kExe = std::string(KNIT_BIN_DIR) + "/knit-meso";

int shell(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

int count_lines(const fs::path& p) {
  std::ifstream in(p);
  int n = 0;
  std::string s;
  while (std::getline(in, s)) ++n;
  return n;
}

int count_job_files(const fs::path& dir) {
  int n = 0;
  if (!fs::exists(dir)) return 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("job_", 0) == 0) ++n;
  return n;
}

}  // namespace

TEST_CASE("knit-meso sweep: bad input exits with 2 and names the JSON pointer", "[case]") {
  const auto dir = knit_test::scratch("sweep_cli_bad");
  knit_test::write_text(dir / "bad.json", R"({"loop_lengths": [5.0, 4.5], "runner": "synthetic"})");
  const std::string log = (dir / "log.txt").string();
  CHECK(shell(kExe + " sweep " + (dir / "bad.json").string() + " --output " +
              (dir / "x.h5").string() + " > " + log + " 2>&1") == 2);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text.find("/loop_lengths/1") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "x.h5"));
}

TEST_CASE(
    "knit-meso sweep: killed midway then resumed recomputes nothing and equals an "
    "uninterrupted run",
    "[case]") {
  const auto dir = knit_test::scratch("sweep_cli_kill");
  knit_test::write_text(dir / "s.json", knit_test::synthetic_sweep_json());
  const fs::path db = dir / "db.h5", parts = dir / "db.h5.parts", count = dir / "count.txt";
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    setenv("KNIT_SWEEP_TEST_DELAY_MS", "150", 1);
    setenv("KNIT_SWEEP_TEST_COUNT_FILE", count.c_str(), 1);
    const std::string in = (dir / "s.json").string(), out = db.string();
    const int fd = ::open("/dev/null", 1);
    dup2(fd, 1);
    dup2(fd, 2);
    execl(kExe.c_str(), kExe.c_str(), "sweep", in.c_str(), "--output", out.c_str(), "--threads",
          "2", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until some (not all) cases are checkpointed, then SIGKILL.
  const auto t0 = std::chrono::steady_clock::now();
  while (count_job_files(parts) < 7 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  kill(pid, SIGKILL);
  int st = 0;
  waitpid(pid, &st, 0);
  REQUIRE(WIFSIGNALED(st));
  const int finished = count_job_files(parts);
  INFO("checkpointed before the kill: " << finished);
  REQUIRE(finished >= 7);
  REQUIRE(finished < 26);
  CHECK_FALSE(fs::exists(db));  // never half-written: not there at all
  // Without --resume the checkpoints are protected.
  CHECK(shell("KNIT_SWEEP_TEST_COUNT_FILE=" + (dir / "ignored.txt").string() + " " + kExe +
              " sweep " + (dir / "s.json").string() + " --output " + db.string() +
              " > /dev/null 2>&1") == 2);
  CHECK_FALSE(fs::exists(dir / "ignored.txt"));
  // Resume: exactly the missing cases are computed.
  fs::remove(count);
  REQUIRE(shell("KNIT_SWEEP_TEST_COUNT_FILE=" + count.string() + " " + kExe + " sweep " +
                (dir / "s.json").string() + " --output " + db.string() +
                " --resume --threads 2 > " + (dir / "resume.log").string() + " 2>&1") == 0);
  CHECK(count_lines(count) == 26 - finished);
  REQUIRE(fs::exists(db));
  CHECK_FALSE(fs::exists(parts));
  // Against an uninterrupted run.
  REQUIRE(shell(kExe + " sweep " + (dir / "s.json").string() + " --output " +
                (dir / "full.h5").string() + " --threads 1 > /dev/null 2>&1") == 0);
  CHECK(knit_test::database_difference(knit::material::read_database(db),
                                       knit::material::read_database(dir / "full.h5")) == 0.0);
}

TEST_CASE("knit-meso sweep: mpirun with 2 ranks gives the serial database", "[case]") {
  if (!knit::meso::sweep::MpiSession::compiled()) {
    WARN("built without MPI: skipped");
    return;
  }
  if (shell("command -v mpirun > /dev/null 2>&1") != 0) {
    WARN("mpirun not found: skipped");
    return;
  }
  const auto dir = knit_test::scratch("sweep_cli_mpi");
  knit_test::write_text(dir / "s.json", knit_test::synthetic_sweep_json());
  const std::string in = (dir / "s.json").string();
  REQUIRE(shell(kExe + " sweep " + in + " --output " + (dir / "serial.h5").string() +
                " --threads 1 > /dev/null 2>&1") == 0);
  const std::string log = (dir / "mpi.log").string();
  const int rc =
      shell("mpirun --allow-run-as-root --oversubscribe -np 2 " + kExe + " sweep " + in +
            " --output " + (dir / "mpi.h5").string() + " --threads 1 > " + log + " 2>&1");
  std::ifstream l(log);
  const std::string text((std::istreambuf_iterator<char>(l)), std::istreambuf_iterator<char>());
  INFO(text);
  REQUIRE(rc == 0);
  CHECK(text.find("2 ranks") != std::string::npos);
  CHECK(knit_test::database_difference(knit::material::read_database(dir / "serial.h5"),
                                       knit::material::read_database(dir / "mpi.h5")) <= 1e-12);
}
