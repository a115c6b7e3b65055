// Independent tasks on the cores (core/parallel_tasks.hpp): every task runs exactly once whatever
// the thread count, and a task's exception reaches the caller after all threads finished.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "core/parallel_tasks.hpp"

namespace {

TEST(ParallelTasks, EveryTaskRunsOnceOnAnyThreadCount) {
  for (unsigned threads : {0u, 1u, 2u, 7u}) {
    std::vector<int> runs(1000, 0);
    imscal::run_parallel_tasks(
        runs.size(), [&](std::size_t i) { runs[i] += int(i % 7) + 1; }, threads);
    for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i], int(i % 7) + 1) << threads;
  }
  std::atomic<int> none{0};
  imscal::run_parallel_tasks(
      0, [&](std::size_t) { ++none; }, 2);
  EXPECT_EQ(none.load(), 0);
}

TEST(ParallelTasks, AnExceptionReachesTheCallerAfterTheOtherTasks) {
  std::atomic<int> done{0};
  const auto task = [&](std::size_t i) {
    if (i == 3) throw std::runtime_error("task 3");
    ++done;
  };
  EXPECT_THROW(imscal::run_parallel_tasks(10, task, 2), std::runtime_error);
  EXPECT_EQ(done.load(), 9);  // the others all ran
}

}  // namespace
