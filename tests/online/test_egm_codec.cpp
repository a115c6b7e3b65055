// The EGM codec (online/egm_codec.hpp) against the protocol-buffer wire format written out by
// hand (truth: the encoding rules of protobuf's documentation, field numbers of egm.proto: tag =
// field << 3 | wire type; doubles as 8 little-endian bytes; ABB's repeated joints unpacked), the
// refusals of datagrams outside the form, and no heap allocation once the codec has seen a
// datagram of the controller's shape.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include "online/egm_codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "tests/support/allocation_counter.hpp"

namespace imscal::online {
namespace {

std::string varint_field(int field, std::uint64_t v) {
  std::string s(1, char(field << 3 | 0));
  do {
    const auto byte = std::uint8_t(v & 0x7f);
    v >>= 7;
    s += char(v ? byte | 0x80 : byte);
  } while (v);
  return s;
}

std::string double_field(int field, double v) {
  std::string s(9, char(field << 3 | 1));
  std::memcpy(s.data() + 1, &v, 8);  // x86-64 and ARM: little-endian, as the wire format
  return s;
}

std::string message_field(int field, const std::string& body) {
  std::string s(2, char(field << 3 | 2));
  s[1] = char(body.size());  // bodies < 128 bytes: a one-byte length
  s.append(body);
  return s;
}

std::string joints(const std::vector<double>& deg) {
  std::string s;
  for (double v : deg) s += double_field(1, v);
  return s;
}

std::string header(std::uint32_t seqno, std::uint32_t tm, int mtype) {
  return varint_field(1, seqno) + varint_field(2, tm) + varint_field(3, std::uint64_t(mtype));
}

TEST(EgmCodec, AnswerIsTheWireFormatWrittenByHand) {
  EgmCodec codec;
  const std::array<double, kEgmAxes> planned{1.5, -2.25, 90.0, 0.0, 1e-6, -179.875};
  std::array<char, 512> buffer{};
  const int n = codec.write_sensor(300, 1200, planned, buffer.data(), int(buffer.size()));
  // EgmSensor { header = 1 {seqno 300, tm 1200, mtype CORRECTION = 3}, planned = 2 {joints = 1}}.
  const std::string expected =
      message_field(1, header(300, 1200, 3)) +
      message_field(2, message_field(1, joints({planned.begin(), planned.end()})));
  ASSERT_EQ(n, int(expected.size()));
  EXPECT_EQ(std::string(buffer.data(), std::size_t(n)), expected);
}

TEST(EgmCodec, ReadsAControllerDatagramWrittenByHand) {
  // EgmRobot { header = 1, feedBack = 2 {joints = 1}, planned = 3 {joints = 1},
  // motorState = 4 {state = 1: ON}, a field imscal does not declare (utilizationRate = 10) }.
  const std::vector<double> feedback{10, 20, 30, 40, 50, 60}, plan{11, 21, 31, 41, 51, 61};
  const std::string bytes = message_field(1, header(77, 308, 2)) +
                            message_field(2, message_field(1, joints(feedback))) +
                            message_field(3, message_field(1, joints(plan))) +
                            message_field(4, varint_field(1, 1)) + double_field(10, 12.5);
  EgmCodec codec;
  EgmRobotDatagram d;
  ASSERT_EQ(codec.parse_robot(bytes, &d), EgmParseError::kNone);
  EXPECT_EQ(d.seqno, 77u);
  EXPECT_EQ(d.tm_ms, 308u);
  ASSERT_EQ(d.feedback_joints, 6);
  ASSERT_EQ(d.planned_joints, 6);
  for (int a = 0; a < 6; ++a) {
    EXPECT_EQ(d.feedback_deg[std::size_t(a)], feedback[std::size_t(a)]);
    EXPECT_EQ(d.planned_deg[std::size_t(a)], plan[std::size_t(a)]);
  }
  EXPECT_EQ(d.motors, EgmMotors::kOn);
}

TEST(EgmCodec, RefusesDatagramsOutsideTheForm) {
  EgmCodec codec;
  EgmRobotDatagram d;
  const std::string feedback = message_field(2, message_field(1, joints({1, 2, 3, 4, 5, 6})));
  EXPECT_EQ(codec.parse_robot(std::string(2000, '\0'), &d), EgmParseError::kTooLong);
  EXPECT_EQ(codec.parse_robot("\x0a\x10\x08\x01", &d), EgmParseError::kNotProtobuf);
  EXPECT_EQ(codec.parse_robot(feedback, &d), EgmParseError::kMissingHeader);
  EXPECT_EQ(codec.parse_robot(message_field(1, header(1, 4, 3)) + feedback, &d),
            EgmParseError::kNotData);
  EXPECT_EQ(codec.parse_robot(message_field(1, header(1, 4, 2)), &d),
            EgmParseError::kMissingFeedback);
  const std::string many = message_field(2, message_field(1, joints(std::vector<double>(13, 1.0))));
  EXPECT_EQ(codec.parse_robot(message_field(1, header(1, 4, 2)) + many, &d),
            EgmParseError::kTooManyJoints);
  // A motor state without its required value is not an EgmRobot.
  EXPECT_EQ(
      codec.parse_robot(message_field(1, header(1, 4, 2)) + feedback + message_field(4, ""), &d),
      EgmParseError::kNotProtobuf);
  std::array<char, 512> buffer{};
  EXPECT_EQ(codec.write_sensor(1, 4, {NAN, 0, 0, 0, 0, 0}, buffer.data(), 512), -1);
  EXPECT_EQ(codec.write_sensor(1, 4, {0, 0, 0, 0, 0, 0}, buffer.data(), 20), -1);
}

TEST(EgmCodec, NoAllocationOnceTheShapeIsKnown) {
  EgmCodec codec;
  std::array<char, 512> in{}, out{};
  EgmRobotDatagram d;
  d.feedback_joints = d.planned_joints = 6;
  d.motors = EgmMotors::kOn;
  long allocations = 0;
  for (std::uint32_t k = 0; k < 1000; ++k) {
    d.seqno = k;
    for (int a = 0; a < 6; ++a) d.feedback_deg[std::size_t(a)] = std::sin(0.01 * k + a);
    const int n = codec.write_robot(d, in.data(), int(in.size()));
    ASSERT_GT(n, 0);
    EgmRobotDatagram parsed;
    const long before = test_support::g_allocations.load();
    ASSERT_EQ(codec.parse_robot(std::string_view(in.data(), std::size_t(n)), &parsed),
              EgmParseError::kNone);
    std::array<double, kEgmAxes> q{};
    for (int a = 0; a < 6; ++a) q[std::size_t(a)] = parsed.feedback_deg[std::size_t(a)];
    ASSERT_GT(codec.write_sensor(parsed.seqno, parsed.tm_ms, q, out.data(), int(out.size())), 0);
    if (k > 0) allocations += test_support::g_allocations.load() - before;  // k = 0: the shape
  }
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace imscal::online
