#pragma once
// The one parallel-for of the project: restarts, sweeps, folds, dataset rows and evaluation screws
// all go through it, so every one of them propagates a worker's exception the same way.
#include <cstddef>
#include <functional>

namespace whirl {

/// Calls `body(i)` for every i in [0, n) on up to `threads` threads (the calling thread is one of
/// them; threads <= 0 means std::thread::hardware_concurrency()). Indices are handed out in
/// increasing order, but completion order is arbitrary: `body` must write only to slot i of
/// pre-sized outputs for the result to be identical for any thread count.
/// The first exception thrown by any `body` (of any type) stops the handing-out of new indices and
/// is rethrown in the caller after all threads have joined; nothing calls std::terminate.
/// `progress(done, n)`, if set, is called under a lock after each completed index.
void ParallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& body,
                 const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace whirl
