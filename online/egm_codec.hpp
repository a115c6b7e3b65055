#pragma once
// ABB EGM (Externally Guided Motion) datagrams: protocol buffers over UDP (online/proto/egm.proto,
// written from ABB's public description). The controller sends an EgmRobot every EGM cycle
// (4 ms): a header (seqno counting the datagrams, tm the controller's time in ms, mtype DATA),
// the measured joints (feedBack), the controller's planned joints and the motors' state. In
// position guidance the sensor answers with an EgmSensor: the header (mtype CORRECTION, the seqno
// of the datagram answered) and the target joints (planned). Angles in degrees.
//
// The codec keeps its protocol-buffer messages between calls: after the first datagram of a
// shape, parsing and writing reuse their storage and do not allocate (fields the controller adds
// beyond egm.proto are kept as unknown bytes in storage that is reused too). Protobuf's types stay
// inside egm_codec.cpp.
#include <array>
#include <cstdint>
#include <memory>
#include <string_view>

namespace imscal::online {

inline constexpr int kEgmAxes = 6;                 // the robot's joints served
inline constexpr int kEgmMaxJoints = 12;           // more in a datagram are refused
inline constexpr int kEgmMaxDatagramBytes = 1400;  // one Ethernet frame; EGM's are ~200 bytes

enum class EgmParseError : std::uint8_t {
  kNone,
  kTooLong,          // more than kEgmMaxDatagramBytes
  kNotProtobuf,      // not an EgmRobot in the wire format (or a required field missing)
  kMissingHeader,    // no header, or no seqno in it
  kNotData,          // header mtype is not MSGTYPE_DATA
  kMissingFeedback,  // no feedBack joints
  kTooManyJoints,    // more than kEgmMaxJoints feedback or planned joints
};
const char* to_string(EgmParseError error);

enum class EgmMotors : std::uint8_t { kUndefined, kOn, kOff };

struct EgmRobotDatagram {
  std::uint32_t seqno = 0;
  std::uint32_t tm_ms = 0;
  int feedback_joints = 0;  // how many of feedback_deg are sent
  std::array<double, kEgmMaxJoints> feedback_deg{};
  int planned_joints = 0;  // the controller's planned joints, when sent
  std::array<double, kEgmMaxJoints> planned_deg{};
  EgmMotors motors = EgmMotors::kUndefined;  // kUndefined when not sent
};

class EgmCodec {
 public:
  EgmCodec();
  EgmCodec(const EgmCodec&) = delete;
  EgmCodec& operator=(const EgmCodec&) = delete;
  ~EgmCodec();

  // One controller datagram into *out (left partly written on refusal). Joint values may be
  // non-finite: the caller judges values, the codec only the form.
  EgmParseError parse_robot(std::string_view bytes, EgmRobotDatagram* out) noexcept;

  // The answer: an EgmSensor (mtype CORRECTION, seqno and tm as given, planned joints) into
  // buffer; its length, or -1 when it does not fit or a joint is not finite.
  int write_sensor(std::uint32_t seqno, std::uint32_t tm_ms,
                   const std::array<double, kEgmAxes>& planned_deg, char* buffer,
                   int capacity) noexcept;

  // The controller's side, for the emulator, the tests and the fuzz target: an EgmRobot from
  // `datagram` (motor state sent unless kUndefined, planned joints unless 0 of them) ...
  int write_robot(const EgmRobotDatagram& datagram, char* buffer, int capacity) noexcept;
  // ... and the sensor's answer read back: false when it is not an EgmSensor with a seqno and
  // kEgmAxes planned joints.
  bool parse_sensor(std::string_view bytes, std::uint32_t* seqno,
                    std::array<double, kEgmAxes>* planned_deg) noexcept;

 private:
  struct Messages;
  std::unique_ptr<Messages> messages_;
};

}  // namespace imscal::online
