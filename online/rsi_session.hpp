#pragma once
// One RSI connection's work per datagram, without the socket: parse the controller's datagram
// (online/rsi_datagram.hpp), judge it (malformed, late, lost / duplicated / reordered IPOC,
// unknown robot), step the precontrol (ident/precontrol.hpp) on the set-points ASPos, and write
// the answer with the IPOC echoed. `imscal serve` puts it behind a UDP socket
// (online/udp_server.hpp); the bench and the tests call it directly too.
//
// Faults: what the session detects itself is reported to the precontrol as a caller fault
// (Precontrol::fault: the corrections fade out over fade_out_s, never stepping above the rate
// limit) and logged in a fixed ring (read_faults); what the precontrol detects (the counter's
// gaps, NaN, a jump of the set-point, its tolerances) is in the precontrol's own event log. The
// precontrol runs with auto_engage: it fades in when the stream starts, also during motion, and
// re-engages after a fault once the input has been valid for reengage_after_s.
//
// A malformed datagram is not answered (its IPOC is not known); the next valid one is answered
// with the correction fading out. A duplicated or reordered datagram (an IPOC not newer than the
// last) is answered with its own IPOC and the correction held, without stepping the precontrol
// (so the commanded path takes no second step in one cycle); the next datagram in order fades
// out.
//
// Units: the datagram's degrees are converted to radians for the precontrol and back.
// Increment mode: the answer is the change of the correction since the last answer, as the
// controller will read it (rounded to the written decimals), so that the controller's sum of the
// increments equals the correction; each increment is held to the rate limit per cycle. The
// answer to a duplicated or reordered datagram is a zero increment: the controller may discard
// it (an answer to a datagram it no longer waits for), and a discarded non-zero increment would
// leave its sum off the correction for good.
//
// No allocation, exception or lock in handle(); create() allocates.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "ident/parameter_table.hpp"
#include "ident/precontrol.hpp"
#include "online/datagram_session.hpp"
#include "online/path_follower.hpp"
#include "online/rsi_datagram.hpp"

namespace imscal::online {

enum class RsiCorrectionMode : std::uint8_t { kAbsolute, kIncrement };

struct RsiSessionOptions {
  RsiCorrectionMode mode = RsiCorrectionMode::kAbsolute;
  double cycle_s = 0.004;              // the controller's RSI cycle
  std::uint64_t ipoc_per_cycle = 4;    // IPOC advance per cycle (KUKA: milliseconds)
  std::string robot_type;              // Rob's Type attribute expected; empty: any
  std::string sensor_type = "ImFree";  // Sen's Type attribute of the answer
  double late_after_s = 0.0;  // > 0: a datagram later than cycle_s + this after the last is late
  double payload_kg = 0.0;    // the payload the precontrol's operating point uses
};

class RsiSession final : public DatagramSession {
 public:
  // nullptr with the reason in *why when the precontrol refuses the table or the options are
  // inconsistent (cycle, IPOC step, sensor type). `path`: the program's desired path, which a
  // table with a preview or the model torque needs (refused without); the precontrol is then fed
  // the path ahead of the set-point, with its torque and payload.
  static std::unique_ptr<RsiSession> create(const ident::ParameterTable& table,
                                            const std::string& robot_name,
                                            ident::PrecontrolOptions precontrol,
                                            const RsiSessionOptions& options, std::string* why,
                                            std::unique_ptr<PathFollower> path = nullptr);

  // One received datagram at receive_time_s (any monotonic clock): the answer's length written
  // to `answer`, or 0 when the datagram is not answered (malformed).
  int handle(std::string_view datagram, double receive_time_s, char* answer,
             int capacity) noexcept override;
  ident::Precontrol& precontrol() noexcept override { return precontrol_; }
  // The correction of the last answer [rad] (absolute, whichever the mode) and its state.
  const std::array<double, kRsiAxes>& correction_rad() const noexcept { return correction_rad_; }
  ident::PrecontrolState state() const noexcept { return state_; }

 private:
  RsiSession() = default;
  // The session's own judgement of a parsed datagram; true when the precontrol must fade out.
  bool judge(const RsiRobotDatagram& datagram, double receive_time_s) noexcept;
  void answer_values(const std::array<double, kRsiAxes>& offset_rad,
                     std::array<double, kRsiAxes>* values_deg) noexcept;

  // The precontrol's input of an in-order datagram (the set-point, or the loaded path ahead);
  // false when it is off the loaded path.
  bool precontrol_input(const std::array<double, kRsiAxes>& setpoint_rad,
                        PathSample* input) noexcept;

  ident::Precontrol precontrol_;
  RsiSessionOptions options_;
  std::unique_ptr<PathFollower> path_;
  std::uint64_t advanced_ = 1;  // cycles since the previous in-order datagram
  RsiRobotDatagram datagram_;
  bool started_ = false;
  bool pending_fault_ = false;  // a malformed datagram since the last answer
  bool in_order_ = true;        // the datagram's IPOC is newer than the previous one's
  std::uint64_t last_cycle_ = 0;
  double last_receive_s_ = 0.0;
  std::array<double, kRsiAxes> correction_rad_{};
  std::array<double, kRsiAxes> sent_sum_deg_{};  // increment mode: what the controller summed
  ident::PrecontrolState state_ = ident::PrecontrolState::kInactive;
};

}  // namespace imscal::online
