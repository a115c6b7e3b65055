// The EGM session without sockets (online/egm_session.hpp): it holds the robot where it stands
// until the robot is at the path's first pose, then answers each datagram with the path's joints
// of the datagram's cycle plus the precontrol's correction (truth: a precontrol of its own fed the
// same path ahead, ident/precontrol.hpp), the seqno and tm echoed; out-of-order datagrams get
// the path at their own cycle with the correction held; no heap allocation in handle().
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include "online/egm_session.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/units.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/lag_table.hpp"

namespace imscal::online {
namespace {

constexpr double kCycle = 0.004;
constexpr std::size_t kAhead = 4;  // path samples the precontrol is fed ahead

LoadedPath swinging_path(std::size_t n) {
  LoadedPath p;
  p.cycle_s = kCycle;
  for (std::size_t k = 0; k < n; ++k) {
    std::array<double, kPathJoints> q{};
    for (int j = 0; j < kPathJoints; ++j)
      q[std::size_t(j)] = 0.2 * std::sin(2.0 * M_PI * double(k) * kCycle / (1.0 + 0.3 * j));
    p.q_rad.push_back(q);
  }
  return p;
}

ident::PrecontrolOptions precontrol_options() {
  ident::PrecontrolOptions o;
  o.offset_tolerance_rad.fill(0.05);
  o.rate_tolerance_rad_s.fill(5.0);
  o.auto_engage = true;
  o.caller_cycle_s = kCycle;
  return o;
}

struct Answer {
  std::uint32_t seqno = 0;
  std::array<double, kEgmAxes> planned_deg{};
};

class EgmSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    session_ = EgmSession::create(test_support::lag_table(-0.9, 0.1), "kr16", precontrol_options(),
                                  {}, swinging_path(kCycles), kAhead * kCycle, &why);
    ASSERT_TRUE(session_) << why;
  }
  // Sends the controller's datagram (seqno, measured joints [rad]); false when not answered.
  bool send(std::uint32_t seqno, const std::array<double, kPathJoints>& q_rad, Answer* out) {
    EgmRobotDatagram d;
    d.seqno = seqno;
    d.tm_ms = 4 * seqno;
    d.feedback_joints = kEgmAxes;
    for (int a = 0; a < kEgmAxes; ++a)
      d.feedback_deg[std::size_t(a)] = q_rad[std::size_t(a)] * kDegPerRad;
    d.motors = EgmMotors::kOn;
    const int n = controller_.write_robot(d, in_.data(), int(in_.size()));
    const long before = test_support::g_allocations.load();
    const int bytes = session_->handle(std::string_view(in_.data(), std::size_t(n)), seqno * kCycle,
                                       out_.data(), int(out_.size()));
    if (seqno > first_) allocations_ += test_support::g_allocations.load() - before;
    if (bytes <= 0) return false;
    return controller_.parse_sensor(std::string_view(out_.data(), std::size_t(bytes)), &out->seqno,
                                    &out->planned_deg);
  }

  static constexpr std::size_t kCycles = 2000;
  std::unique_ptr<EgmSession> session_;
  EgmCodec controller_;
  std::array<char, 512> in_{}, out_{};
  long allocations_ = 0;
  std::uint32_t first_ = 10;
};

TEST_F(EgmSessionTest, HoldsTheRobotUntilItIsAtTheStartThenPlaysThePathPlusTheCorrection) {
  const LoadedPath path = swinging_path(kCycles);
  std::array<double, kPathJoints> away = path.q_rad[0];
  away[2] += 0.01;  // 10 mrad off the start pose
  Answer a;
  ASSERT_TRUE(send(first_ - 2, away, &a));
  EXPECT_FALSE(session_->following());
  for (int j = 0; j < kEgmAxes; ++j)  // held where it stands
    EXPECT_DOUBLE_EQ(a.planned_deg[std::size_t(j)], away[std::size_t(j)] * kDegPerRad);
  ASSERT_TRUE(send(first_ - 1, path.q_rad[0], &a));  // the robot moved to the start
  EXPECT_TRUE(session_->following());
  std::array<SessionFaultEvent, 8> faults{};
  ASSERT_GE(session_->read_faults(faults.data(), 8), 1);
  EXPECT_EQ(faults[0].fault, SessionFault::kNotAtStart);
  EXPECT_NEAR(faults[0].value, 0.01, 1e-12);

  // Truth: a precontrol of its own, fed the path kAhead samples ahead from the start's seqno.
  ident::Precontrol truth;
  std::string why;
  ASSERT_TRUE(ident::Precontrol::create(test_support::lag_table(-0.9, 0.1), "kr16",
                                        precontrol_options(), &truth, &why));
  double largest = 0.0;
  for (std::size_t k = 0; k + 1 < 1000; ++k) {
    const std::uint32_t seqno = first_ - 1 + std::uint32_t(k);
    ident::PrecontrolOutput expected;
    if (k > 0) {
      ASSERT_TRUE(send(seqno, path.q_rad[k - 1], &a));  // measured: the last target
    }
    expected = truth.cycle(path.q_rad[k + kAhead], 0.0, seqno);
    if (k == 0) continue;  // answered above
    ASSERT_EQ(a.seqno, seqno);
    for (int j = 0; j < kEgmAxes; ++j) {
      const double c = path.q_rad[k][std::size_t(j)] + expected.offset_rad[std::size_t(j)];
      // Through degrees and back: a few ulps of 0.2 rad.
      ASSERT_NEAR(a.planned_deg[std::size_t(j)] / kDegPerRad, c, 1e-15) << k;
      largest = std::max(largest, std::abs(expected.offset_rad[std::size_t(j)]));
    }
  }
  EXPECT_GT(largest, 1e-3);  // not compared at zero: the lag's correction is mrad
  EXPECT_EQ(session_->state(), ident::PrecontrolState::kActive);
  EXPECT_EQ(allocations_, 0);
}

TEST_F(EgmSessionTest, OutOfOrderGetsThePathAtItsOwnCycleWithTheCorrectionHeld) {
  const LoadedPath path = swinging_path(kCycles);
  Answer a;
  for (std::uint32_t k = 0; k < 300; ++k) ASSERT_TRUE(send(first_ + k, path.q_rad[k], &a));
  const std::array<double, kEgmAxes> held = session_->correction_rad();
  ASSERT_TRUE(send(first_ + 297, path.q_rad[297], &a));  // reordered
  EXPECT_EQ(a.seqno, first_ + 297);
  for (int j = 0; j < kEgmAxes; ++j)
    EXPECT_NEAR(a.planned_deg[std::size_t(j)] / kDegPerRad,
                path.q_rad[297][std::size_t(j)] + held[std::size_t(j)], 1e-15);
  std::array<SessionFaultEvent, 8> faults{};
  ASSERT_EQ(session_->read_faults(faults.data(), 8), 1);
  EXPECT_EQ(faults[0].fault, SessionFault::kReordered);
}

TEST(EgmSession, RefusesAPathThatDoesNotFitTheCycle) {
  std::string why;
  LoadedPath path = swinging_path(10);
  path.cycle_s = 0.003;  // 4 ms is not a whole number of 3 ms samples
  EXPECT_FALSE(EgmSession::create(test_support::lag_table(-0.9, 0.1), "kr16", precontrol_options(),
                                  {}, path, 0.0, &why));
  EXPECT_NE(why.find("whole numbers"), std::string::npos) << why;
  EXPECT_FALSE(EgmSession::create(test_support::lag_table(-0.9, 0.1), "kr16", precontrol_options(),
                                  {}, LoadedPath{}, 0.0, &why));
}

}  // namespace
}  // namespace imscal::online
