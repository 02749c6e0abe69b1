#include "util/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace dgmm {

void ParallelFor(int n, int threads, const std::function<void(int)>& f) {
  std::atomic<int> next{0};
  std::mutex mu;
  std::atomic<bool> failed{false};
  std::exception_ptr failure;
  auto worker = [&] {
    for (int t = next++; t < n && !failed; t = next++) {
      try {
        f(t);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!failure) failure = std::current_exception();
        failed = true;
      }
    }
  };
  const int k = std::max(1, std::min(threads, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < k; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace dgmm
