// The persistent assembly threads (thread_pool.hpp), the shell's per-thread workspaces kept
// across evaluations and models (shell_model.cpp: no allocation after the first call) and the
// scatter into the reduced tangent split by value range between threads (reduced_tangent.hpp).
#include <atomic>
#include <catch2/catch.hpp>
#include <random>
#include <stdexcept>

#include "knit/macro/case.hpp"
#include "knit/macro/reduced_tangent.hpp"
#include "knit/macro/run.hpp"
#include "knit/macro/thread_pool.hpp"
#include "shell_test_util.hpp"

using namespace knit::macro;
using knit::macro::test::curved_patch;
using knit::macro::test::dense_tangent;

TEST_CASE("the thread pool runs every task once per call, on distinct threads", "[unit]") {
  ThreadPool pool(2);
  CHECK(pool.size() == 2);
  for (int n : {1, 2, 4, 3, 1, 4}) {  // grows to 4 threads on demand, then keeps them
    std::vector<int> hits(n, 0);
    std::vector<std::thread::id> who(n);
    pool.run(n, [&](int k) {
      ++hits[k];
      who[k] = std::this_thread::get_id();
    });
    for (int k = 0; k < n; ++k) CHECK(hits[k] == 1);
    CHECK(who[0] == std::this_thread::get_id());
    for (int k = 1; k < n; ++k)
      for (int j = 0; j < k; ++j) CHECK(who[k] != who[j]);
  }
  CHECK(pool.size() == 4);
  // Many short calls (the design's many small evaluations): no lost wake-up, no deadlock.
  std::atomic<long> sum{0};
  for (int it = 0; it < 2000; ++it) pool.run(2 + it % 3, [&](int k) { sum += k + 1; });
  long expect = 0;
  for (int it = 0; it < 2000; ++it) expect += (2 + it % 3) * (3 + it % 3) / 2;
  CHECK(sum == expect);
}

TEST_CASE("an exception of a pool task reaches the caller after all tasks finished", "[unit]") {
  ThreadPool pool(3);
  std::atomic<int> finished{0};
  CHECK_THROWS_WITH(pool.run(3,
                             [&](int k) {
                               if (k == 1) throw std::runtime_error("task 1");
                               ++finished;
                             }),
                    "task 1");
  CHECK(finished == 2);
  pool.run(3, [&](int) { ++finished; });  // still usable
  CHECK(finished == 5);
}

namespace {
Eigen::VectorXd random_u(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-0.05, 0.05);
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u(i) = d(gen);
  return u;
}
}  // namespace

TEST_CASE("the shell's kept workspaces give the result of fresh ones across models", "[unit]") {
  // Models of different degrees (and a rational one: the direct product, no Y) evaluated in
  // turn on the same threads: each evaluation bitwise equal to the first of its model, which
  // ran with a workspace made for it.
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  const int threads = GENERATE(1, 2);
  ShellModel a(curved_patch(2, 3, 3, 2, 2.0, 1.5, 0.4, false), 0.1, mat);
  ShellModel b(curved_patch(4, 4, 2, 2, 2.0, 1.5, 0.4, false), 0.1, mat);
  ShellModel c(curved_patch(3, 2, 2, 3, 2.0, 1.5, 0.4, true), 0.1, mat);
  ShellModel* models[3] = {&a, &b, &c};
  ShellModel::Evaluation first[3], again;
  for (int k = 0; k < 3; ++k) {
    models[k]->set_threads(threads);
    models[k]->evaluate(random_u(models[k]->num_dofs(), 3 + k), true, first[k]);
    REQUIRE(first[k].ok);
  }
  for (int round = 0; round < 2; ++round)
    for (int k : {2, 0, 1}) {
      ShellModel& m = *models[k];
      m.evaluate(random_u(m.num_dofs(), 3 + k), true, again);
      REQUIRE(again.ok);
      CHECK((again.fint - first[k].fint).norm() == 0.0);
      CHECK((dense_tangent(m, again) - dense_tangent(m, first[k])).norm() == 0.0);
    }
}

TEST_CASE("the scatter split between threads gives the one-thread matrix bitwise", "[unit]") {
  // Every storage (dense / sparse, LU / lower triangle) of the Sze cantilever's tangent at a
  // deformed state, assembled on 1, 2 and 3 threads: K x bitwise the same (each value is
  // summed in element order by the thread that owns it).
  Case c = load_case(std::string(KNIT_SOURCE_DIR) + "/cases/verification/sze_cantilever.json");
  const Problem p = setup_problem(c);
  ShellModel& m = *p.model;
  ShellModel::Evaluation ev;
  m.evaluate(random_u(m.num_dofs(), 9), true, ev);
  REQUIRE(ev.ok);
  const Eigen::VectorXd x = random_u(p.dofs.num_free(), 10);
  for (const bool sparse : {false, true})
    for (const bool symmetric : {false, true}) {
      m.set_threads(1);
      ReducedTangent K1(m, p.dofs, symmetric, sparse);
      REQUIRE(K1.scatter_threads() == 1);
      K1.assemble(ev.Ke);
      K1.assemble(ev.Ke);  // values reset by assemble
      const Eigen::VectorXd y1 = K1.multiply(x);
      REQUIRE(y1.norm() > 0.0);
      for (const int threads : {2, 3}) {
        m.set_threads(threads);
        ReducedTangent K(m, p.dofs, symmetric, sparse);
        CHECK(K.scatter_threads() == threads);
        K.assemble(ev.Ke);
        K.assemble(ev.Ke);
        CHECK((K.multiply(x) - y1).norm() == 0.0);
      }
    }
}

TEST_CASE("the scatter straight from the element kernel gives the matrix of assemble() bitwise",
          "[unit]") {
  // ReducedTangent as the model's ElementTangentSink (no element tangents stored; entries of
  // values that an earlier thread's elements touch held back until the threads joined) against
  // assemble(Ke) of a stored evaluation (the reference), every storage, 1, 2 and 3 threads, from
  // evaluate() and from tangent_from(); twice each (the values are reset).
  Case c = load_case(std::string(KNIT_SOURCE_DIR) + "/cases/verification/sze_cantilever.json");
  const Problem p = setup_problem(c);
  ShellModel& m = *p.model;
  const Eigen::VectorXd u = random_u(m.num_dofs(), 9);
  ShellModel::Evaluation ev, direct, residual;
  m.set_threads(1);
  m.evaluate(u, true, ev);
  REQUIRE(ev.ok);
  const Eigen::VectorXd x = random_u(p.dofs.num_free(), 10);
  for (const bool sparse : {false, true})
    for (const bool symmetric : {false, true})
      for (const int threads : {1, 2, 3}) {
        CAPTURE(sparse, symmetric, threads);
        m.set_threads(1);
        ReducedTangent ref(m, p.dofs, symmetric, sparse);
        ref.assemble(ev.Ke);
        const Eigen::VectorXd y = ref.multiply(x);
        REQUIRE(y.norm() > 0.0);
        m.set_threads(threads);
        ReducedTangent K(m, p.dofs, symmetric, sparse);
        for (int round = 0; round < 2; ++round) {
          K.begin_assembly(m);
          m.evaluate(u, true, direct, false, &K);
          REQUIRE(direct.ok);
          CHECK(direct.Ke.empty());
          K.end_assembly();
          CHECK((K.multiply(x) - y).norm() == 0.0);
          m.evaluate(u, false, residual, true);
          K.begin_assembly(m);
          m.tangent_from(residual, direct, &K);
          K.end_assembly();
          CHECK((K.multiply(x) - y).norm() == 0.0);
        }
        m.set_threads(threads == 1 ? 2 : 1);
        CHECK_THROWS_AS(K.begin_assembly(m), std::logic_error);
      }
}
