#include "online/egm_session.hpp"

#include <algorithm>
#include <cmath>

#include "core/units.hpp"

namespace imscal::online {

std::unique_ptr<EgmSession> EgmSession::create(const ident::ParameterTable& table,
                                               const std::string& robot_name,
                                               ident::PrecontrolOptions precontrol,
                                               const EgmSessionOptions& options, LoadedPath path,
                                               double ahead_s, std::string* why) {
  auto refuse = [&](const std::string& reason) {
    if (why) *why = reason;
    return std::unique_ptr<EgmSession>();
  };
  if (!(options.cycle_s > 0.0)) return refuse("the EGM cycle must be > 0 s");
  if (path.q_rad.empty()) return refuse("the loaded path has no samples");
  if (!(path.cycle_s > 0.0)) return refuse("the loaded path's sample spacing must be > 0 s");
  if (!path.torque_nm.empty() && path.torque_nm.size() != path.q_rad.size())
    return refuse("the loaded path's torques are not one per sample");
  if (!path.payload_kg.empty() && path.payload_kg.size() != path.q_rad.size())
    return refuse("the loaded path's payloads are not one per sample");
  const long per_cycle = whole_samples(options.cycle_s, path.cycle_s);
  const long ahead = whole_samples(ahead_s, path.cycle_s);
  if (per_cycle < 1 || ahead < 0)
    return refuse(
        "the EGM cycle and the preview must be whole numbers of the path's sample spacing");
  precontrol.caller_cycle_s = options.cycle_s;
  precontrol.auto_engage = true;
  std::unique_ptr<EgmSession> session(new EgmSession());
  std::string reason;
  if (!ident::Precontrol::create(table, robot_name, precontrol, &session->precontrol_, &reason))
    return refuse(reason);
  if (session->precontrol_.needs_model_torque() && path.torque_nm.empty())
    return refuse("the table's models take the model torque: the loaded path has none");
  session->options_ = options;
  session->path_ = std::move(path);
  session->samples_per_cycle_ = std::size_t(per_cycle);
  session->ahead_samples_ = std::size_t(ahead);
  return session;
}

bool EgmSession::feedback_faulty(const EgmRobotDatagram& d) noexcept {
  if (d.feedback_joints != kEgmAxes) {
    record(d.seqno, SessionFault::kUnknownRobot, d.feedback_joints, 0.0);
    return true;
  }
  double largest = 0.0;
  for (int a = 0; a < kEgmAxes; ++a) {
    const double q = d.feedback_deg[std::size_t(a)];
    if (!std::isfinite(q)) {
      record(d.seqno, SessionFault::kBadFeedback, a, q);
      return true;
    }
    if (has_target_) largest = std::max(largest, std::abs(q - target_deg_[std::size_t(a)]));
  }
  if (largest / kDegPerRad > options_.track_tolerance_rad) {
    record(d.seqno, SessionFault::kBadFeedback, -1, largest / kDegPerRad);
    return true;
  }
  return false;
}

bool EgmSession::judge(const EgmRobotDatagram& d, double receive_time_s) noexcept {
  in_order_ = !started_ || d.seqno > last_seqno_;
  if (!in_order_) {
    record(d.seqno, d.seqno == last_seqno_ ? SessionFault::kDuplicated : SessionFault::kReordered,
           0, double(last_seqno_ - d.seqno));
    pending_fault_ = true;
    return false;
  }
  bool fade = pending_fault_;
  pending_fault_ = false;
  if (feedback_faulty(d)) fade = true;
  if (d.motors == EgmMotors::kOff) {
    record(d.seqno, SessionFault::kMotorsOff, 0, 0.0);
    fade = true;
  }
  if (started_) {
    const double gap_s = receive_time_s - last_receive_s_;
    if (options_.late_after_s > 0.0 && gap_s > options_.cycle_s + options_.late_after_s) {
      record(d.seqno, SessionFault::kLate, 0, gap_s);
      fade = true;
    }
    // The precontrol's own counter check fades out on a gap; logged here by kind too.
    if (d.seqno > last_seqno_ + 1)
      record(d.seqno, SessionFault::kLost, 0, double(d.seqno - last_seqno_ - 1));
  }
  started_ = true;
  last_seqno_ = d.seqno;
  last_receive_s_ = receive_time_s;
  return fade;
}

std::size_t EgmSession::path_index(std::uint32_t seqno) const noexcept {
  return std::size_t(seqno - first_seqno_) * samples_per_cycle_;
}

bool EgmSession::try_start(const EgmRobotDatagram& d) noexcept {
  double largest = 0.0;
  for (int a = 0; a < kEgmAxes; ++a)
    largest = std::max(largest, std::abs(d.feedback_deg[std::size_t(a)] / kDegPerRad -
                                         path_.q_rad.front()[std::size_t(a)]));
  if (d.feedback_joints >= kEgmAxes && largest <= options_.start_tolerance_rad) {
    following_ = true;
    first_seqno_ = d.seqno;
    return true;
  }
  // Held where it stands (its measured joints, when they are usable).
  record(d.seqno, SessionFault::kNotAtStart, 0, largest);
  if (d.feedback_joints >= kEgmAxes && std::isfinite(largest)) {
    for (int a = 0; a < kEgmAxes; ++a) target_deg_[std::size_t(a)] = d.feedback_deg[std::size_t(a)];
    has_target_ = true;
  }
  return false;
}

void EgmSession::step_following(const EgmRobotDatagram& d, bool fade) noexcept {
  const std::size_t last = path_.q_rad.size() - 1;
  const std::size_t now = std::min(path_index(d.seqno), last);
  const std::size_t ahead = std::min(path_index(d.seqno) + ahead_samples_, last);
  const double payload_kg =
      path_.payload_kg.empty() ? options_.payload_kg : path_.payload_kg[ahead];
  if (fade) precontrol_.fault(d.seqno, 0.0);
  const ident::PrecontrolOutput out =
      precontrol_.needs_model_torque()
          ? precontrol_.cycle(path_.q_rad[ahead], payload_kg, path_.torque_nm[ahead], d.seqno)
          : precontrol_.cycle(path_.q_rad[ahead], payload_kg, d.seqno);
  state_ = out.state;
  for (int a = 0; a < kEgmAxes; ++a) {
    const auto i = std::size_t(a);
    correction_rad_[i] = out.offset_rad[i];
    target_deg_[i] = (path_.q_rad[now][i] + out.offset_rad[i]) * kDegPerRad;
  }
  has_target_ = true;
}

int EgmSession::handle(std::string_view datagram, double receive_time_s, char* answer,
                       int capacity) noexcept {
  const EgmParseError error = codec_.parse_robot(datagram, &datagram_);
  if (error != EgmParseError::kNone) {
    record(0, SessionFault::kMalformed, int(error), 0.0);
    pending_fault_ = true;
    return refuse_datagram();
  }
  const bool fade = judge(datagram_, receive_time_s);
  std::array<double, kEgmAxes> joints_deg = target_deg_;
  if (in_order_) {
    if (following_ || try_start(datagram_)) step_following(datagram_, fade);
    joints_deg = target_deg_;
  } else if (following_ && datagram_.seqno >= first_seqno_) {
    // Out of order: the path at the datagram's own cycle, the correction held.
    const std::size_t k = std::min(path_index(datagram_.seqno), path_.q_rad.size() - 1);
    for (int a = 0; a < kEgmAxes; ++a)
      joints_deg[std::size_t(a)] =
          (path_.q_rad[k][std::size_t(a)] + correction_rad_[std::size_t(a)]) * kDegPerRad;
  }
  if (!has_target_) return refuse_datagram();  // nothing to hold the robot at yet
  return counted_answer(
      codec_.write_sensor(datagram_.seqno, datagram_.tm_ms, joints_deg, answer, capacity));
}

}  // namespace imscal::online
