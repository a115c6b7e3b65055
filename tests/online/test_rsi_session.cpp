// The RSI session without sockets (online/rsi_session.hpp): no heap allocation in handle(), for
// good and bad datagrams alike; the increment mode's answers sum to the absolute mode's
// corrections (truth: a second session in absolute mode on the same datagrams); options the
// controller cannot use are refused at creation.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include "online/rsi_session.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <string>

#include "online/controller_emulator.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/lag_table.hpp"

namespace imscal::online {
namespace {

ident::ParameterTable lag_table() {
  return test_support::lag_table(-0.9, 0.1);
}

std::unique_ptr<RsiSession> make(RsiCorrectionMode mode) {
  RsiSessionOptions o;
  o.mode = mode;
  ident::PrecontrolOptions p;
  p.offset_tolerance_rad.fill(0.05);
  p.rate_tolerance_rad_s.fill(5.0);
  std::string why;
  auto session = RsiSession::create(lag_table(), "kr16", p, o, &why);
  EXPECT_TRUE(session) << why;
  return session;
}

// Cycle k's datagram of a swinging motion (IPOC 4 k), into `buffer`.
std::string_view datagram(std::size_t k, std::array<char, 1024>& buffer) {
  std::array<double, kRsiAxes> q_deg{};
  for (int a = 0; a < kRsiAxes; ++a) q_deg[std::size_t(a)] = 5.0 * std::sin(0.01 * k + a);
  const int n = write_rsi_robot_datagram("KUKA", q_deg, 4 * k, buffer.data(), int(buffer.size()));
  return {buffer.data(), std::size_t(n)};
}

std::array<double, kRsiAxes> read_korr(std::string_view answer) {
  std::array<double, kRsiAxes> v{};
  for (int a = 0; a < kRsiAxes; ++a) {
    const std::string key = " A" + std::to_string(a + 1) + "=\"";
    const std::size_t at = answer.find(key) + key.size();
    std::from_chars(answer.data() + at, answer.data() + answer.size(), v[std::size_t(a)]);
  }
  return v;
}

TEST(RsiSession, HandlesDatagramsWithoutAllocating) {
  auto session = make(RsiCorrectionMode::kIncrement);
  std::vector<std::array<char, 1024>> datagrams(2000);
  std::vector<std::string_view> text(datagrams.size());
  for (std::size_t k = 0; k < datagrams.size(); ++k) text[k] = datagram(k, datagrams[k]);
  const std::string malformed = "<Rob><IPOC>1</IPOC>";
  std::array<char, 1024> answer{};
  int answered = 0;
  const long before = test_support::g_allocations.load();
  for (std::size_t k = 0; k < text.size(); ++k) {
    // Every 100th cycle a fault: malformed, a repeat of the last datagram, a gap.
    if (k % 300 == 100) session->handle(malformed, 0.0, answer.data(), int(answer.size()));
    if (k % 300 == 200) session->handle(text[k - 1], 0.0, answer.data(), int(answer.size()));
    if (k % 300 == 250) continue;
    answered += session->handle(text[k], 0.0, answer.data(), int(answer.size())) > 0;
  }
  EXPECT_EQ(test_support::g_allocations.load() - before, 0);
  EXPECT_GT(answered, 1900);
  std::array<SessionFaultEvent, kSessionFaultCapacity> faults{};
  EXPECT_GT(session->read_faults(faults.data(), int(faults.size())), 10);
}

TEST(RsiSession, IncrementsSumToTheAbsoluteCorrection) {
  auto absolute = make(RsiCorrectionMode::kAbsolute);
  auto increment = make(RsiCorrectionMode::kIncrement);
  std::array<char, 1024> in{}, out{};
  std::array<double, kRsiAxes> sum{};
  double largest = 0.0;
  for (std::size_t k = 0; k < 1500; ++k) {
    const std::string_view text = datagram(k, in);
    const int n = absolute->handle(text, 0.0, out.data(), int(out.size()));
    ASSERT_GT(n, 0);
    const auto a = read_korr({out.data(), std::size_t(n)});
    const int m = increment->handle(text, 0.0, out.data(), int(out.size()));
    ASSERT_GT(m, 0);
    const auto d = read_korr({out.data(), std::size_t(m)});
    for (int j = 0; j < kRsiAxes; ++j) {
      sum[std::size_t(j)] += d[std::size_t(j)];
      largest = std::max(largest, std::abs(a[std::size_t(j)]));
      // Both written to 1e-6 degree: the sum within one unit of the absolute value.
      ASSERT_NEAR(sum[std::size_t(j)], a[std::size_t(j)], 1.0001e-6) << k;
    }
  }
  EXPECT_GT(largest, 0.01);  // degrees: the corrections are not all zero
}

TEST(RsiSession, RefusesOptionsTheControllerCannotUse) {
  std::string why;
  RsiSessionOptions o;
  o.ipoc_per_cycle = 0;
  EXPECT_FALSE(RsiSession::create(lag_table(), "kr16", {}, o, &why));
  o = {};
  o.sensor_type = "Im\"Free";
  EXPECT_FALSE(RsiSession::create(lag_table(), "kr16", {}, o, &why));
  o = {};
  o.cycle_s = 0.003;  // not a multiple of the table's 2 ms
  EXPECT_FALSE(RsiSession::create(lag_table(), "kr16", {}, o, &why));
  EXPECT_NE(why.find("caller cycle"), std::string::npos) << why;
  EXPECT_FALSE(RsiSession::create(lag_table(), "ur10", {}, RsiSessionOptions{}, &why));
}

}  // namespace
}  // namespace imscal::online
