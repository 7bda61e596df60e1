// A persistent pool of worker threads for the shell's assembly (docs/solver.md "Threads").
// The threads are started once per process (ThreadPool::shared(), grown on demand) and wait on
// a condition variable between calls: starting threads per evaluation cost every call a clone,
// a fresh stack and its page faults (the inverse design's many small forward solves, each with
// models of its own).
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace knit::macro {

class ThreadPool {
 public:
  /// `threads` >= 1 in all, the caller included (threads - 1 workers are started).
  explicit ThreadPool(int threads = 1);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// The process-wide pool (no worker until a run() needs one).
  static ThreadPool& shared();

  /// Threads in all (the caller included).
  int size() const;
  /// Runs task(k) for k = 0 .. n - 1: task 0 on the calling thread, task k on worker k - 1
  /// (started here if the pool has fewer); returns when every task has finished. An exception
  /// of a task is rethrown here (that of the lowest k) after all have finished. Calls are
  /// serialized: a second caller waits for the first (a task must not call run()).
  void run(int n, const std::function<void(int)>& task);

 private:
  /// Worker k's loop; `seen`: the last generation (call) it need not take.
  void work(int k, long seen);

  std::mutex run_mu_;  ///< one run() at a time
  mutable std::mutex mu_;
  std::condition_variable start_, done_;
  const std::function<void(int)>* task_ = nullptr;
  int n_ = 0;
  long generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
  std::vector<std::exception_ptr> errors_;
  std::vector<std::thread> workers_;
};

}  // namespace knit::macro
