// The request memory budget (server/memory.hpp): its accounting, and the
// parse-cost factor it charges per message byte against what parsing really
// allocates (glibc's mallinfo2) for the costliest JSON shapes.
#include <gtest/gtest.h>

#include <malloc.h>

#include <string>
#include <vector>

#include "protocol/bounded_json.hpp"
#include "server/memory.hpp"

namespace beamcast {
namespace {

std::size_t heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

// `n` copies of `element`, comma-separated, between `open` and `close`.
std::string repeated(const std::string& open, const std::string& element, const std::string& close,
                     int n) {
  std::string s = open;
  for (int i = 0; i < n; ++i) {
    if (i) s += ',';
    s += element;
  }
  return s + close;
}

TEST(RequestMemory, ParseCostFactorBoundsTheCostliestShapes) {
#if defined(BEAMCAST_ASAN)
  // ASan replaces glibc's malloc, whose mallinfo2 this measures (it reads 0
  // there); the default build measures it.
  GTEST_SKIP() << "measures glibc's allocator, which AddressSanitizer replaces";
#endif
  const int n = 200'000;
  std::vector<std::string> shapes = {
      repeated("[", "{}", "]", n),        // 27 bytes per byte measured
      repeated("[", "[]", "]", n),        // 16
      repeated("[", "\"\"", "]", n),      // 22
      repeated("[", "[0]", "]", n),       // 20
      repeated("[", "{\"a\":0}", "]", n), // 22
      repeated("[", "1", "]", n),         // 8
  };
  std::string members = "{";
  for (int i = 0; i < n; ++i) members += (i ? ",\"k" : "\"k") + std::to_string(i) + "\":{}";
  shapes.push_back(members + "}");
  JsonLimits limits;
  limits.max_values = 10'000'000;
  double worst = 0;
  for (const std::string& text : shapes) {
    const std::size_t before = heap_in_use();
    const BoundedParse parsed = parse_json_bounded(text, limits);
    ASSERT_FALSE(parsed.error) << parsed.error->message;
    const double cost = static_cast<double>(heap_in_use() - before);
    // The estimate covers the document (the text is counted in it too).
    EXPECT_LE(cost, static_cast<double>(MemoryBudget::estimate(text.size())))
        << text.substr(0, 20) << "...: " << cost / static_cast<double>(text.size()) << " per byte";
    worst = std::max(worst, cost / static_cast<double>(text.size()));
  }
  // Not so loose that it refuses much the server could parse: the worst
  // shape (27-28 per byte) costs at least 0.6 of the factor.
  EXPECT_GE(worst, 0.6 * kParseCostFactor) << worst;
}

TEST(RequestMemory, BudgetAdmitsUntilFullThenBusyAndRefusesWhatNeverFits) {
  MemoryBudget budget(100 * kParseCostFactor);
  MemoryBudget::Reservation a, b, c;
  ErrorInfo e;
  ASSERT_TRUE(budget.try_reserve(60, &a, &e));
  EXPECT_EQ(budget.in_use(), 60 * kParseCostFactor);
  EXPECT_FALSE(budget.try_reserve(41, &b, &e));
  EXPECT_EQ(e.code, "busy");
  EXPECT_NE(e.message.find("max_request_memory_bytes"), std::string::npos) << e.message;
  ASSERT_TRUE(budget.try_reserve(40, &b, &e));
  EXPECT_FALSE(budget.try_reserve(101, &c, &e));
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_NE(e.message.find("max_request_memory_bytes"), std::string::npos) << e.message;
  a.release();
  a.release();  // once only
  EXPECT_EQ(budget.in_use(), 40 * kParseCostFactor);
  {
    MemoryBudget::Reservation moved = std::move(b);
    EXPECT_EQ(budget.in_use(), 40 * kParseCostFactor);
  }  // released by its new owner
  EXPECT_EQ(budget.in_use(), 0u);
  EXPECT_TRUE(budget.try_reserve(100, &c, &e));
}

}  // namespace
}  // namespace beamcast
