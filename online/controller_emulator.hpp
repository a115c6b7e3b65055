#pragma once
// The controller's side of KUKA RSI or ABB EGM, for tests and benches without a robot: sends one
// datagram per cycle, the counter (RSI: IPOC; EGM: seqno) advancing by ipoc_per_cycle, waits
// for the answer with the same counter and collects the corrections as a controller would apply
// them. Lock-step (the next datagram as soon as the answer came) or paced at the cycle.
//  - RSI: the datagram carries the set-points of a joint path (ASPos; AIPos the same, the
//    emulator has no encoders); the corrections are absolute or summed from increments.
//  - EGM (position guidance): the datagram carries the measured joints (feedBack), here the
//    path's joints of the cycle, as a robot that follows its targets; the answer's target joints
//    minus the path's are the corrections (the server plays the same path, online/egm_session.hpp).
//
// Faults are injected at chosen cycles: a dropped datagram (the cycle's IPOC never sent), a
// duplicated one, two swapped, a malformed one (instead of the cycle's), a NaN or a jump of the
// set-point, a late one, a wrong robot type. The plant (eval/closed_loop.hpp) is then run on
// q_d + correction, cycle by cycle the data flow of the robot: the precontrol sees only the
// set-points, so the plant's response does not feed back into the answers.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "online/rsi_session.hpp"
#include "online/udp_socket.hpp"

namespace imscal::online {

enum class InjectedFault : std::uint8_t {
  kDrop,          // the cycle's datagram is not sent
  kDuplicate,     // sent twice
  kSwapWithNext,  // the next cycle's datagram is sent first
  kMalformed,     // a broken datagram instead of the cycle's (then the cycle's, late)
  kNaN,           // RSI: ASPos A1 = nan; EGM: feedBack A1 = nan
  kJump,          // RSI: ASPos A1 + jump_deg; EGM: feedBack A1 + jump_deg, for this cycle
  kLate,          // sent late_delay_s late
  kUnknownRobot,  // RSI: Rob Type = "UNKNOWN"; EGM: 7 feedBack joints
};

enum class ControllerProtocol : std::uint8_t { kRsi, kEgm };

struct EmulatorOptions {
  ControllerProtocol protocol = ControllerProtocol::kRsi;
  RsiCorrectionMode mode = RsiCorrectionMode::kAbsolute;
  double cycle_s = 0.004;
  std::uint64_t first_ipoc = 1000;   // EGM: the first seqno
  std::uint64_t ipoc_per_cycle = 4;  // EGM: 1
  std::string robot_type = "KUKA";
  bool paced = false;                           // true: one datagram every cycle_s (steady clock)
  double answer_timeout_s = 0.5;                // a cycle without an answer by then is missed
  double late_delay_s = 0.05;                   // kLate
  double jump_deg = 5.0;                        // kJump
  std::map<std::size_t, InjectedFault> faults;  // by cycle index
};

struct EmulatorRun {
  // Per cycle of the path: the correction the controller applies [rad] (held from the last
  // answer when a cycle has none), whether the cycle's own datagram was answered, and the time
  // from sending it to its answer [s] (0 when not answered).
  std::vector<std::array<double, kRsiAxes>> correction_rad;
  std::vector<bool> answered;
  std::vector<double> latency_s;
  std::size_t missed = 0;  // cycles whose datagram was sent and not answered in time
};

// setpoint_rad: one entry per cycle. Throws std::runtime_error when the socket fails.
EmulatorRun emulate_controller(UdpSocket& socket, const UdpPeer& server,
                               const std::vector<std::array<double, kRsiAxes>>& setpoint_rad,
                               const EmulatorOptions& options);

// The controller's datagram of one cycle (what the emulator sends), into buffer: its length.
int write_rsi_robot_datagram(std::string_view robot_type,
                             const std::array<double, kRsiAxes>& setpoint_deg, std::uint64_t ipoc,
                             char* buffer, int capacity);

}  // namespace imscal::online
