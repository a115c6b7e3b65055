// The RSI datagram codec (online/rsi_datagram.hpp): a controller datagram of the documented
// layout is read exactly; every way of breaking it is refused with its typed reason (every
// prefix, every single-byte corruption: accepted or refused, never read past the end, which the
// sanitizer build checks); the answer is written in the documented layout and reads back.
#include "online/rsi_datagram.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "online/controller_emulator.hpp"

namespace imscal::online {
namespace {

const std::string kDatagram =
    "<Rob Type=\"KUKA\">\n"
    "  <RIst X=\"445.0\" Y=\"0.0\" Z=\"890.0\" A=\"180.0\" B=\"0.0\" C=\"180.0\"/>\n"
    "  <RSol X=\"445.0\" Y=\"0.0\" Z=\"890.0\" A=\"180.0\" B=\"0.0\" C=\"180.0\"/>\n"
    "  <AIPos A1=\"0.5\" A2=\"-90.25\" A3=\"90.125\" A4=\"-1e-3\" A5=\"45\" A6=\"+0.0\"/>\n"
    "  <ASPos A1=\"0.5001\" A2=\"-90.2501\" A3=\"90.1251\" A4=\"0.0\" A5=\"45.0\" A6=\"-180.0\"/>\n"
    "  <EIPos E1=\"0.0\" E2=\"0.0\"/>\n"
    "  <Delay D=\"0\"/>\n"
    "  <IPOC>4294967296000</IPOC>\n"
    "</Rob>\n";

RsiParseError parse(const std::string& text) {
  RsiRobotDatagram d;
  return parse_rsi_robot_datagram(text, &d);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(RsiDatagram, ReadsTheDocumentedLayout) {
  RsiRobotDatagram d;
  ASSERT_EQ(parse_rsi_robot_datagram(kDatagram, &d), RsiParseError::kNone);
  EXPECT_EQ(d.type_name(), "KUKA");
  EXPECT_EQ(d.ipoc, 4294967296000ull);  // beyond 32 bits
  const std::array<double, 6> setpoint{0.5001, -90.2501, 90.1251, 0.0, 45.0, -180.0};
  const std::array<double, 6> actual{0.5, -90.25, 90.125, -1e-3, 45.0, 0.0};
  EXPECT_EQ(d.setpoint_deg, setpoint);  // decimal text to the nearest double: exact
  ASSERT_TRUE(d.has_actual);
  EXPECT_EQ(d.actual_deg, actual);
}

TEST(RsiDatagram, AcceptsPrologCommentsSingleQuotesAndNoActualValues) {
  const std::string text =
      "<?xml version='1.0'?><!-- cycle --><Rob TYPE='KR16'><ASPos A6='6' A5='5' A4='4' A3='3' "
      "A2='2' A1='1'/><!-- x --><IPOC> 17 </IPOC></Rob><!-- end -->";
  RsiRobotDatagram d;
  ASSERT_EQ(parse_rsi_robot_datagram(text, &d), RsiParseError::kNone);
  EXPECT_EQ(d.type_name(), "KR16");
  EXPECT_EQ(d.ipoc, 17u);
  EXPECT_EQ(d.setpoint_deg[5], 6.0);
  EXPECT_FALSE(d.has_actual);
}

TEST(RsiDatagram, NonFiniteValuesAreReadForTheSupervisorToJudge) {
  RsiRobotDatagram d;
  ASSERT_EQ(parse_rsi_robot_datagram(replaced(kDatagram, "A1=\"0.5001\"", "A1=\"nan\""), &d),
            RsiParseError::kNone);
  EXPECT_TRUE(std::isnan(d.setpoint_deg[0]));
}

TEST(RsiDatagram, RefusesEachBrokenFormWithItsReason) {
  EXPECT_EQ(parse(""), RsiParseError::kMalformedXml);
  EXPECT_EQ(parse("<Sen Type=\"x\"><IPOC>1</IPOC></Sen>"), RsiParseError::kNotRob);
  EXPECT_EQ(parse(replaced(kDatagram, "<IPOC>4294967296000</IPOC>", "")),
            RsiParseError::kMissingIpoc);
  EXPECT_EQ(parse(replaced(kDatagram, "4294967296000", "12a")), RsiParseError::kBadIpoc);
  EXPECT_EQ(parse(replaced(kDatagram, "4294967296000", "-1")), RsiParseError::kBadIpoc);
  EXPECT_EQ(parse(replaced(kDatagram, "4294967296000", "184467440737095516160")),
            RsiParseError::kBadIpoc);  // beyond 64 bits
  EXPECT_EQ(parse(replaced(kDatagram, "4294967296000", "")), RsiParseError::kBadIpoc);
  EXPECT_EQ(parse(replaced(kDatagram, "<IPOC>4294967296000</IPOC>", "<IPOC><x/>1</IPOC>")),
            RsiParseError::kBadIpoc);
  EXPECT_EQ(parse(replaced(kDatagram, "<ASPos", "<ASPosX")), RsiParseError::kMissingSetpoint);
  EXPECT_EQ(parse(replaced(kDatagram, " A6=\"-180.0\"", "")), RsiParseError::kMissingAxis);
  EXPECT_EQ(parse(replaced(kDatagram, "A2=\"-90.2501\"", "A2=\"1.2.3\"")),
            RsiParseError::kBadNumber);
  EXPECT_EQ(parse(replaced(kDatagram, "A2=\"-90.2501\"", "A2=\"\"")), RsiParseError::kBadNumber);
  EXPECT_EQ(parse(replaced(kDatagram, "A2=\"-90.2501\"", "A1=\"0\"")),
            RsiParseError::kMalformedXml);
  EXPECT_EQ(parse(replaced(kDatagram, "<Delay D=\"0\"/>", "<IPOC>1</IPOC>")),
            RsiParseError::kRepeatedElement);
  EXPECT_EQ(parse(replaced(kDatagram, "</Rob>", "</Robo>")), RsiParseError::kMalformedXml);
  EXPECT_EQ(parse(kDatagram + "<Rob/>"), RsiParseError::kMalformedXml);
  EXPECT_EQ(parse(replaced(kDatagram, "KUKA", std::string(40, 'K'))), RsiParseError::kTypeTooLong);
  EXPECT_EQ(parse(replaced(kDatagram, "<Delay D=\"0\"/>",
                           "<a><a><a><a><a><a><a><a></a></a></a></a></a></a></a></a>")),
            RsiParseError::kTooDeep);
  EXPECT_EQ(parse(replaced(kDatagram, "<Delay D=\"0\"/>", std::string(5000, ' '))),
            RsiParseError::kTooLong);
}

TEST(RsiDatagram, EveryPrefixAndEveryByteCorruptionIsAcceptedOrRefusedCleanly) {
  // Each proper prefix lacks the closing </Rob>: refused. A corrupted byte may still leave a
  // valid datagram (a digit for a digit); the count of refusals shows the check is not vacuous.
  for (std::size_t n = 0; n < kDatagram.size() - 1; ++n)
    ASSERT_NE(parse(kDatagram.substr(0, n)), RsiParseError::kNone) << n;
  int refused = 0;
  for (std::size_t i = 0; i < kDatagram.size(); ++i) {
    for (char c : {'<', '>', '"', '/', '\0', 'x', '='}) {
      std::string text = kDatagram;
      text[i] = c;
      refused += parse(text) != RsiParseError::kNone;
    }
  }
  EXPECT_GT(refused, int(kDatagram.size()));
}

TEST(RsiDatagram, WritesTheAnswerInTheDocumentedLayout) {
  std::array<char, 512> buffer{};
  const int n = write_rsi_answer("ImFree", {0.0123456789, -1.5, 0.0, -0.0000004, 1e-7, 360.0}, 4321,
                                 buffer.data(), int(buffer.size()));
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(buffer.data(), std::size_t(n)),
            "<Sen Type=\"ImFree\"><AKorr A1=\"0.012346\" A2=\"-1.500000\" A3=\"0.000000\" "
            "A4=\"0.000000\" A5=\"0.000000\" A6=\"360.000000\"/><IPOC>4321</IPOC></Sen>");
  EXPECT_EQ(rsi_written_value(0.0123456789), 0.012346);
}

TEST(RsiDatagram, RefusesAnAnswerThatCannotBeWritten) {
  std::array<char, 512> buffer{};
  const std::array<double, 6> zero{};
  EXPECT_EQ(write_rsi_answer("ImFree", zero, 1, buffer.data(), 40), -1);  // too small
  EXPECT_EQ(write_rsi_answer("Im\"Free", zero, 1, buffer.data(), 512), -1);
  std::array<double, 6> nan = zero;
  nan[3] = std::nan("");
  EXPECT_EQ(write_rsi_answer("ImFree", nan, 1, buffer.data(), 512), -1);
}

TEST(RsiDatagram, TheEmulatorsDatagramReadsBackToItsValues) {
  std::array<char, 2048> buffer{};
  const std::array<double, 6> q{12.3456789, -0.5, 90.0, -179.9999994, 0.0, 1.0};
  const int n = write_rsi_robot_datagram("KUKA", q, 77, buffer.data(), int(buffer.size()));
  ASSERT_GT(n, 0);
  RsiRobotDatagram d;
  ASSERT_EQ(parse_rsi_robot_datagram(std::string_view(buffer.data(), std::size_t(n)), &d),
            RsiParseError::kNone);
  EXPECT_EQ(d.ipoc, 77u);
  // Written with 6 decimals: within half a unit of the last one.
  for (int a = 0; a < 6; ++a) EXPECT_NEAR(d.setpoint_deg[std::size_t(a)], q[std::size_t(a)], 5e-7);
}

}  // namespace
}  // namespace imscal::online
