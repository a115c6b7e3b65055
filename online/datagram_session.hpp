#pragma once
// The work per datagram of a controller interface (KUKA RSI: online/rsi_session.hpp, ABB EGM:
// online/egm_session.hpp) behind the UDP server loop (online/udp_server.hpp): the answer to one
// received datagram, the precontrol it steps, and the log of the faults the session detects
// itself (a fixed ring: no allocation when a fault is recorded in the cycle).
#include <array>
#include <cstdint>
#include <string_view>

#include "ident/precontrol.hpp"

namespace imscal::online {

enum class SessionFault : std::uint8_t {
  kMalformed,     // detail: the parser's error (RsiParseError, EgmParseError)
  kLate,          // value: the gap to the previous datagram [s]
  kLost,          // value: cycles missing before this counter
  kDuplicated,    // the counter of the previous datagram again
  kReordered,     // a counter older than the previous one
  kUnknownRobot,  // RSI: Rob's Type is not the expected one; EGM: not kEgmAxes feedback joints
  kOffPath,       // RSI: the set-point is not on the loaded path at its time
  kBadFeedback,   // EGM: a measured joint not finite or off the commanded one; value: |diff| [rad]
  kMotorsOff,     // EGM: the controller reports its motors off
  kNotAtStart,    // EGM: the robot is not at the path's first pose; value: largest |diff| [rad]
};
const char* to_string(SessionFault fault);

struct SessionFaultEvent {
  std::uint64_t counter = 0;  // RSI: IPOC; EGM: seqno (0 for a malformed datagram)
  SessionFault fault = SessionFault::kMalformed;
  int detail = 0;
  double value = 0.0;
};
inline constexpr int kSessionFaultCapacity = 256;

class DatagramSession {
 public:
  DatagramSession() = default;
  DatagramSession(const DatagramSession&) = delete;
  DatagramSession& operator=(const DatagramSession&) = delete;
  virtual ~DatagramSession() = default;

  // One received datagram at receive_time_s (any monotonic clock): the answer's length written
  // to `answer`, or 0 when the datagram is not answered.
  virtual int handle(std::string_view datagram, double receive_time_s, char* answer,
                     int capacity) noexcept = 0;
  virtual ident::Precontrol& precontrol() noexcept = 0;

  // Faults since the last call, oldest first (the ring keeps the newest kSessionFaultCapacity).
  int read_faults(SessionFaultEvent* out, int capacity) noexcept;
  // Datagrams answered, and not answered (malformed, nothing to answer, no room for the answer).
  std::uint64_t answered() const noexcept { return answered_; }
  std::uint64_t refused() const noexcept { return refused_; }

 protected:
  void record(std::uint64_t counter, SessionFault fault, int detail, double value) noexcept;
  // A datagram left unanswered: 0, the length handle() returns for it.
  int refuse_datagram() noexcept {
    ++refused_;
    return 0;
  }
  // The answer's length as the protocol's writer gave it (<= 0: it could not be written).
  int counted_answer(int bytes) noexcept {
    if (bytes <= 0) return refuse_datagram();
    ++answered_;
    return bytes;
  }

 private:
  std::uint64_t answered_ = 0, refused_ = 0;
  std::array<SessionFaultEvent, kSessionFaultCapacity> faults_{};
  int fault_head_ = 0, fault_count_ = 0;
};

}  // namespace imscal::online
