#pragma once
// One ABB EGM connection's work per datagram, without the socket, for position guidance
// (RAPID: EGMActJoint / EGMRunJoint): the controller sends an EgmRobot every cycle and moves the
// robot to the joints of the answer (EgmSensor planned). In this mode the controller has no path
// of its own to correct (its planned joints are the targets it was sent), so the session is the
// path's source: it plays the robot program's desired path, loaded beforehand, and answers each
// datagram with the path's joints at the datagram's cycle plus the precontrol's correction. The
// precontrol (ident/precontrol.hpp, with auto_engage) is fed the path ahead by the table's
// preview, exactly: the path and its clock are the session's own (docs/decisions/0033).
//
// The path's clock: it starts with the first in-order datagram whose measured joints (feedBack)
// stand at the path's first pose (within start_tolerance_rad); until then the answer holds the
// robot where it stands (its measured joints) and the fault is logged. From then on the path
// advances with the seqno, one cycle per seqno (lost datagrams counted), and holds its last sample
// at its end.
//
// Faults, as online/rsi_session.hpp: malformed (not answered), late, lost, duplicated or
// reordered seqno (answered with the path at the datagram's own cycle plus the correction held,
// no precontrol step), measured joints not finite or farther than track_tolerance_rad from the
// previous answer's target (a jump), motors reported off, a robot with other than kEgmAxes
// joints: the corrections fade out (never stepping above the rate limit) and the fault is logged.
//
// The answer's header echoes the datagram's seqno and tm. No exception or lock in handle(), and
// no allocation once the codec has seen the controller's datagram shape (online/egm_codec.hpp).
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "ident/parameter_table.hpp"
#include "ident/precontrol.hpp"
#include "online/datagram_session.hpp"
#include "online/egm_codec.hpp"
#include "online/path_follower.hpp"

namespace imscal::online {

struct EgmSessionOptions {
  double cycle_s = 0.004;     // the controller's EGM cycle
  double late_after_s = 0.0;  // > 0: a datagram later than cycle_s + this after the last is late
  double payload_kg = 0.0;    // the payload when the path has none
  double start_tolerance_rad = 1e-3;  // "at the path's first pose", per joint
  // A measured joint farther than this from the previous answer's target is a fault: above the
  // robot's tracking lag at the program's speed (EGM's filter and the servo lag).
  double track_tolerance_rad = 0.05;
};

class EgmSession final : public DatagramSession {
 public:
  // nullptr with the reason in *why when the precontrol refuses the table, or the path or the
  // options do not fit (the cycle and ahead_s whole numbers of the path's spacing).
  // ahead_s: how far ahead of the answered joints the precontrol is fed (the table's preview and
  // the look-ahead, as `imscal verify`).
  static std::unique_ptr<EgmSession> create(const ident::ParameterTable& table,
                                            const std::string& robot_name,
                                            ident::PrecontrolOptions precontrol,
                                            const EgmSessionOptions& options, LoadedPath path,
                                            double ahead_s, std::string* why);

  int handle(std::string_view datagram, double receive_time_s, char* answer,
             int capacity) noexcept override;
  ident::Precontrol& precontrol() noexcept override { return precontrol_; }

  // The correction of the last in-order answer [rad] and the precontrol's state.
  const std::array<double, kEgmAxes>& correction_rad() const noexcept { return correction_rad_; }
  ident::PrecontrolState state() const noexcept { return state_; }
  bool following() const noexcept { return following_; }

 private:
  EgmSession() = default;
  // The session's judgement of a parsed datagram; true when the precontrol must fade out.
  bool judge(const EgmRobotDatagram& datagram, double receive_time_s) noexcept;
  bool feedback_faulty(const EgmRobotDatagram& datagram) noexcept;
  // The path's sample index at a seqno (following only).
  std::size_t path_index(std::uint32_t seqno) const noexcept;
  // The answer's joints [deg] for an in-order datagram while following.
  void step_following(const EgmRobotDatagram& datagram, bool fade) noexcept;
  bool try_start(const EgmRobotDatagram& datagram) noexcept;

  ident::Precontrol precontrol_;
  EgmSessionOptions options_;
  LoadedPath path_;
  std::size_t samples_per_cycle_ = 1, ahead_samples_ = 0;
  EgmCodec codec_;
  EgmRobotDatagram datagram_;
  bool started_ = false, following_ = false, has_target_ = false;
  bool pending_fault_ = false;  // a malformed datagram since the last answer
  bool in_order_ = true;
  std::uint32_t last_seqno_ = 0, first_seqno_ = 0;
  double last_receive_s_ = 0.0;
  std::array<double, kEgmAxes> target_deg_{};  // the last in-order answer's joints
  std::array<double, kEgmAxes> correction_rad_{};
  ident::PrecontrolState state_ = ident::PrecontrolState::kInactive;
};

}  // namespace imscal::online
