// A bounded cache of material laws keyed by the stitch value l, for the points the shell does
// not bind (the output samples, the design sensitivities' l +- h). Session 29: the paper law's
// response surfaces were kept for every distinct l the samples met, 485 MB on a 201 x 201
// grid with l graded both ways (about 12 GB at the schema's 1001 x 1001); the energy law's
// cache (session 28) kept its first 64 and rebuilt the others at every call.
//
// Two parts:
//   * kept: the first `kept` laws built, for the run's life (a grid of output samples meets the
//     same l at every output step, and building a response surface costs about 0.6 ms);
//   * recent: a ring of the last `recent` laws built beyond that, so the calls for one sample
//     (the section's 3 thickness points and output_fields) build its law once.
// Memory: at most kept + recent laws, whatever the grid. Thread-safe (one mutex; the law is
// built under it, as before).
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace knit::macro {

template <class Law>
class LawCache {
 public:
  LawCache(std::size_t kept, std::size_t recent) : kept_(kept), recent_(recent) {}

  /// The law at l: a cached one, or build(l) (then cached as described above).
  template <class Build>
  std::shared_ptr<const Law> get(double l, Build&& build) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = map_.find(l); it != map_.end()) return it->second;
    for (const auto& r : recent_)
      if (r.second && r.first == l) return r.second;
    std::shared_ptr<const Law> law = build(l);
    if (map_.size() < kept_)
      map_.emplace(l, law);
    else if (!recent_.empty()) {
      recent_[next_] = {l, law};
      next_ = (next_ + 1) % recent_.size();
    }
    return law;
  }

  /// Laws held now (kept and recent; for tests).
  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t n = map_.size();
    for (const auto& r : recent_) n += r.second ? 1 : 0;
    return n;
  }

 private:
  std::size_t kept_;
  mutable std::mutex mutex_;
  mutable std::map<double, std::shared_ptr<const Law>> map_;
  mutable std::vector<std::pair<double, std::shared_ptr<const Law>>> recent_;
  mutable std::size_t next_ = 0;
};

}  // namespace knit::macro
