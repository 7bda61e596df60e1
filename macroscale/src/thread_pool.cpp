#include "knit/macro/thread_pool.hpp"

#include <algorithm>

namespace knit::macro {

ThreadPool::ThreadPool(int threads) {
  std::lock_guard<std::mutex> lock(mu_);
  for (int k = 1; k < threads; ++k) workers_.emplace_back([this, k] { work(k, 0); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : workers_) t.join();
}

ThreadPool& ThreadPool::shared() {
  static ThreadPool pool;
  return pool;
}

int ThreadPool::size() const {
  std::lock_guard<std::mutex> lock(mu_);
  return static_cast<int>(workers_.size()) + 1;
}

void ThreadPool::work(int k, long seen) {
  for (;;) {
    const std::function<void(int)>* task = nullptr;
    {
      std::unique_lock<std::mutex> lock(mu_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (k < n_) task = task_;
    }
    if (!task) continue;  // not needed in this call (and not counted in pending_)
    try {
      (*task)(k);
    } catch (...) {
      errors_[k] = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (--pending_ == 0) done_.notify_one();
    }
  }
}

void ThreadPool::run(int n, const std::function<void(int)>& task) {
  if (n <= 0) return;
  std::lock_guard<std::mutex> serial(run_mu_);
  if (errors_.size() < static_cast<size_t>(n)) errors_.resize(n);
  std::fill(errors_.begin(), errors_.begin() + n, nullptr);
  if (n > 1) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      // Missing workers, started as having seen the last generation: they take this call's.
      for (int k = static_cast<int>(workers_.size()) + 1; k < n; ++k)
        workers_.emplace_back([this, k, g = generation_] { work(k, g); });
      task_ = &task;
      n_ = n;
      pending_ = n - 1;
      ++generation_;
    }
    start_.notify_all();
  }
  try {
    task(0);
  } catch (...) {
    errors_[0] = std::current_exception();
  }
  if (n > 1) {
    std::unique_lock<std::mutex> lock(mu_);
    done_.wait(lock, [&] { return pending_ == 0; });
    task_ = nullptr;
    n_ = 0;
  }
  for (int k = 0; k < n; ++k)
    if (errors_[k]) std::rethrow_exception(errors_[k]);
}

}  // namespace knit::macro
