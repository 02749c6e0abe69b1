#pragma once
// A fixed-size pool for independent tasks: f(0) .. f(n - 1) on up to `threads` threads, each
// taking the next undone index. Callers that need results independent of the thread count write
// task t's result to slot t and reduce in index order.
#include <functional>

namespace dgmm {

// Runs f(0) .. f(n - 1) on up to `threads` threads (the caller's among them). Once a task has
// thrown, no further task is started; the first exception is rethrown after the running tasks
// have finished.
void ParallelFor(int n, int threads, const std::function<void(int)>& f);

}  // namespace dgmm
