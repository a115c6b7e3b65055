#pragma once
// Independent tasks 0..count-1 on the machine's cores: each task runs once, on whichever thread
// takes it next; the calling thread takes tasks too. A task writes only its own results (by its
// index), so the outcome does not depend on the order. The first exception a task throws is
// rethrown after all threads have finished.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace imscal {

// threads 0: one per core (std::thread::hardware_concurrency).
template <typename Task>
void run_parallel_tasks(std::size_t count, const Task& task, unsigned threads = 0) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        task(i);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const std::size_t helpers = std::min<std::size_t>(threads, std::max<std::size_t>(count, 1)) - 1;
  {
    std::vector<std::jthread> pool;
    for (std::size_t i = 0; i < helpers; ++i) pool.emplace_back(work);
    work();
  }  // joins
  if (error) std::rethrow_exception(error);
}

}  // namespace imscal
