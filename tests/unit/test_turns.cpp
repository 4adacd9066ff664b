// Turns inside a long render (protocol/turns.hpp) and the CPU loop that
// offers them (gi/parallel.hpp, parallel_items_with_turns): a due hook runs
// on the caller's thread while no item is in progress, the items' results
// are those of parallel_items, and without a hook nothing is offered.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "gi/parallel.hpp"
#include "protocol/turns.hpp"

namespace beamcast {
namespace {

// A hook that is always due and records, at each turn, how many items were
// in progress (must be 0) and on which thread it ran.
struct CountingHook final : TurnHook {
  const std::atomic<int>* in_progress = nullptr;
  int turns = 0;
  int busy_during_turns = 0;
  bool nested_hook_seen = false;
  std::thread::id thread;
  bool due() override { return true; }
  void take() override {
    ++turns;
    busy_during_turns += in_progress->load();
    nested_hook_seen = nested_hook_seen || turn_hook_installed();
    thread = std::this_thread::get_id();
  }
};

std::vector<int> squares_with(int count, TurnHook* hook, std::atomic<int>& in_progress,
                              int* befores) {
  std::vector<int> out(static_cast<std::size_t>(count), -1);
  const TurnScope scope(hook);
  parallel_items_with_turns(
      count, 2,
      [&](int i) {
        in_progress.fetch_add(1);
        std::this_thread::sleep_for(std::chrono::microseconds(300));
        out[static_cast<std::size_t>(i)] = i * i;
        in_progress.fetch_sub(1);
      },
      [&] { ++*befores; }, std::chrono::milliseconds(1));
  return out;
}

// 200 items of 0.3 ms on 2 threads (~30 ms) offered a turn every 1 ms: the
// turns run between items on the caller's thread, `before` first each time,
// and no hook is installed inside a turn. Without turn points in the loop
// (plain parallel_items) the hook is never taken: turns == 0 fails.
TEST(Turns, ALongLoopGivesTurnsBetweenItemsOnTheCallersThread) {
  std::atomic<int> in_progress{0};
  CountingHook hook;
  hook.in_progress = &in_progress;
  int befores = 0;
  const std::vector<int> out = squares_with(200, &hook, in_progress, &befores);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)], i * i);
  EXPECT_GE(hook.turns, 2);
  EXPECT_EQ(befores, hook.turns);
  EXPECT_EQ(hook.busy_during_turns, 0) << "an item ran during a turn";
  EXPECT_FALSE(hook.nested_hook_seen) << "a turn could take turns itself";
  EXPECT_EQ(hook.thread, std::this_thread::get_id());
  EXPECT_FALSE(turn_hook_installed()) << "the scope put the previous (no) hook back";
}

// No hook: the same results and no turn, and turn_point is false.
TEST(Turns, WithoutAHookNothingIsOffered) {
  std::atomic<int> in_progress{0};
  int befores = 0;
  const std::vector<int> out = squares_with(50, nullptr, in_progress, &befores);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)], i * i);
  EXPECT_EQ(befores, 0);
  EXPECT_FALSE(turn_point([] {}));
}

// An item's exception and a turn's exception both reach the caller after
// every worker has stopped (no thread is left waiting on a paused loop).
TEST(Turns, FailuresInItemsOrTurnsReachTheCaller) {
  struct Throwing final : TurnHook {
    bool due() override { return true; }
    void take() override { throw std::runtime_error("turn failed"); }
  } throwing;
  {
    const TurnScope scope(&throwing);
    EXPECT_THROW(parallel_items_with_turns(
                     1000, 2, [](int) { std::this_thread::sleep_for(std::chrono::microseconds(200)); },
                     [] {}, std::chrono::milliseconds(1)),
                 std::runtime_error);
  }
  CountingHook hook;
  std::atomic<int> none{0};
  hook.in_progress = &none;
  const TurnScope scope(&hook);
  EXPECT_THROW(parallel_items_with_turns(
                   100, 2,
                   [](int i) {
                     std::this_thread::sleep_for(std::chrono::microseconds(200));
                     if (i == 60) throw std::logic_error("item failed");
                   },
                   [] {}, std::chrono::milliseconds(1)),
               std::logic_error);
}

}  // namespace
}  // namespace beamcast
