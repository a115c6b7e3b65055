#pragma once
// KUKA RSI (Robot Sensor Interface) datagrams: the XML text the controller sends every cycle
// (4 ms or 12 ms) over UDP, and the sensor's answer, as publicly documented for RSI's Ethernet
// object (ETHERNET with an XML configuration; layout as in the open-source kuka_rsi_hw_interface):
//
//   controller -> sensor  <Rob Type="KUKA"><RIst X=".." .../><AIPos A1=".." ... A6=".."/>
//                         <ASPos A1=".." ... A6=".."/><Delay D="0"/><IPOC>4321</IPOC></Rob>
//   sensor -> controller  <Sen Type="ImFree"><AKorr A1=".." ... A6=".."/><IPOC>4321</IPOC></Sen>
//
// Angles in degrees (the controller's unit for rotary axes). AIPos: the actual axis positions;
// ASPos: the set-points of the interpolator; IPOC: the controller's cycle time stamp, which the
// answer must echo. AKorr: the axis corrections, either absolute (the whole correction) or
// per-cycle increments that the controller sums, as its RSI configuration sets.
//
// The parser reads the subset of XML these datagrams use (elements, attributes with '"' or '\''
// quotes, text, an optional <?xml ...?> prolog and comments; no DTD, no entity other than the
// five predefined ones, which only skipped content may hold) into a fixed-size struct without
// allocating: it runs in every control cycle. Other elements and attributes are skipped; a
// datagram outside the subset is refused with a typed reason, never read past its end.
#include <array>
#include <cstdint>
#include <string_view>

namespace imscal::online {

inline constexpr int kRsiAxes = 6;
inline constexpr int kRsiMaxDatagramBytes = 4096;  // RSI datagrams are well below 1 kB
inline constexpr int kRsiMaxDepth = 8;             // element nesting accepted
inline constexpr int kRsiMaxTypeBytes = 32;        // the Rob element's Type attribute

enum class RsiParseError : std::uint8_t {
  kNone,
  kTooLong,          // more than kRsiMaxDatagramBytes
  kMalformedXml,     // not well-formed in the subset above (unclosed tag, bad quote, ...)
  kTooDeep,          // nesting beyond kRsiMaxDepth
  kNotRob,           // the root element is not <Rob>
  kMissingIpoc,      // no <IPOC> element
  kBadIpoc,          // IPOC text is not an unsigned integer
  kMissingSetpoint,  // no <ASPos> element
  kMissingAxis,      // an ASPos / AIPos without all of A1..A6
  kBadNumber,        // an axis value that is not a number
  kRepeatedElement,  // IPOC, ASPos or AIPos twice
  kTypeTooLong,      // Rob's Type attribute longer than kRsiMaxTypeBytes
};
const char* to_string(RsiParseError error);

struct RsiRobotDatagram {
  std::array<char, kRsiMaxTypeBytes> type{};  // Rob's Type attribute (type_bytes of them)
  int type_bytes = 0;
  std::uint64_t ipoc = 0;
  std::array<double, kRsiAxes> setpoint_deg{};  // ASPos A1..A6
  bool has_actual = false;
  std::array<double, kRsiAxes> actual_deg{};  // AIPos A1..A6, when sent

  std::string_view type_name() const { return {type.data(), std::size_t(type_bytes)}; }
};

// Parses one controller datagram into *out (left partly written on refusal). Numbers may be
// non-finite ("nan", "inf"): the caller's supervisor judges values, the parser only the form.
RsiParseError parse_rsi_robot_datagram(std::string_view text, RsiRobotDatagram* out) noexcept;

// The answer: writes <Sen Type="sensor_type"><AKorr A1=".." .../><IPOC>ipoc</IPOC></Sen> into
// buffer (fixed-point degrees, kRsiCorrectionDecimals decimals) and returns its length, or -1
// when it does not fit, a correction is not finite, or sensor_type needs escaping.
inline constexpr int kRsiCorrectionDecimals = 6;  // 1e-6 deg = 1.7e-8 rad
int write_rsi_answer(std::string_view sensor_type,
                     const std::array<double, kRsiAxes>& correction_deg, std::uint64_t ipoc,
                     char* buffer, int capacity) noexcept;

// The value the controller reads back from a written correction (rounded to the decimals
// above): what the increment mode accumulates, so that the sum does not drift.
double rsi_written_value(double correction_deg) noexcept;

}  // namespace imscal::online
