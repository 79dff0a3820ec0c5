// runPieces (core/thread_pool.h): every piece runs exactly once, at the same
// time as the others (a piece that waits for all the others would hang if
// they ran one after the other), piece 0 on the caller's thread, and a
// piece's exception reaches the caller after every piece is done.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/thread_pool.h"

namespace fibscope {
namespace {

TEST(RunPieces, EveryPieceRunsOnceAndAllAtTheSameTime) {
  constexpr unsigned kPieces = 5;
  std::vector<std::atomic<int>> runs(kPieces);
  std::atomic<unsigned> arrived{0};
  std::thread::id first_thread;
  runPieces(kPieces, [&](unsigned i) {
    runs[i]++;
    if (i == 0) first_thread = std::this_thread::get_id();
    // A barrier: with the pieces run one after another this never opens
    // (the deadline turns a hang into a failure).
    arrived++;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (arrived.load() < kPieces && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  });
  EXPECT_EQ(arrived.load(), kPieces);
  for (unsigned i = 0; i < kPieces; ++i) EXPECT_EQ(runs[i].load(), 1) << "piece " << i;
  EXPECT_EQ(first_thread, std::this_thread::get_id());
}

TEST(RunPieces, AnExceptionReachesTheCallerAfterEveryPieceFinished) {
  std::atomic<int> finished{0};
  EXPECT_THROW(runPieces(4,
                         [&](unsigned i) {
                           if (i == 2) throw std::runtime_error("piece 2");
                           std::this_thread::sleep_for(std::chrono::milliseconds(50));
                           finished++;
                         }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 3);
}

TEST(RunPieces, NoPiecesRunsNothing) {
  int runs = 0;
  runPieces(0, [&](unsigned) { ++runs; });
  EXPECT_EQ(runs, 0);
}

}  // namespace
}  // namespace fibscope
