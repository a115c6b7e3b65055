#include "online/rsi_session.hpp"

#include <algorithm>
#include <cmath>

#include "core/units.hpp"

namespace imscal::online {
std::unique_ptr<RsiSession> RsiSession::create(const ident::ParameterTable& table,
                                               const std::string& robot_name,
                                               ident::PrecontrolOptions precontrol,
                                               const RsiSessionOptions& options, std::string* why,
                                               std::unique_ptr<PathFollower> path) {
  auto refuse = [&](const std::string& reason) {
    if (why) *why = reason;
    return std::unique_ptr<RsiSession>();
  };
  if (!(options.cycle_s > 0.0)) return refuse("the RSI cycle must be > 0 s");
  if (options.ipoc_per_cycle == 0) return refuse("the IPOC step per cycle must be > 0");
  for (char c : options.sensor_type)
    if (c == '"' || c == '<' || c == '&') return refuse("the sensor type has '\"', '<' or '&'");
  if (options.sensor_type.size() > 64) return refuse("the sensor type is longer than 64 bytes");
  precontrol.caller_cycle_s = options.cycle_s;
  precontrol.auto_engage = true;
  std::unique_ptr<RsiSession> session(new RsiSession());
  std::string reason;
  if (!ident::Precontrol::create(table, robot_name, precontrol, &session->precontrol_, &reason))
    return refuse(reason);
  if (!path && (table.preview_cycles > 0 || session->precontrol_.needs_model_torque()))
    return refuse(
        "the table takes the desired path ahead or the model torque: load the program's "
        "path");
  session->options_ = options;
  session->path_ = std::move(path);
  return session;
}

bool RsiSession::judge(const RsiRobotDatagram& d, double receive_time_s) noexcept {
  const std::uint64_t cycle = d.ipoc / options_.ipoc_per_cycle;
  in_order_ = !started_ || cycle > last_cycle_;
  if (!in_order_) {
    // Not for the precontrol (its counter and its state stay); faded at the next in-order one.
    record(d.ipoc, cycle == last_cycle_ ? SessionFault::kDuplicated : SessionFault::kReordered, 0,
           double(last_cycle_ - cycle));
    pending_fault_ = true;
    return false;
  }
  bool fade = pending_fault_;
  pending_fault_ = false;
  if (!options_.robot_type.empty() && d.type_name() != options_.robot_type) {
    record(d.ipoc, SessionFault::kUnknownRobot, 0, 0.0);
    fade = true;
  }
  if (started_) {
    const double gap_s = receive_time_s - last_receive_s_;
    if (options_.late_after_s > 0.0 && gap_s > options_.cycle_s + options_.late_after_s) {
      record(d.ipoc, SessionFault::kLate, 0, gap_s);
      fade = true;
    }
    // The precontrol's own counter check fades out on a gap; it is logged here by kind too.
    if (cycle > last_cycle_ + 1)
      record(d.ipoc, SessionFault::kLost, 0, double(cycle - last_cycle_ - 1));
  }
  advanced_ = started_ ? cycle - last_cycle_ : 1;
  started_ = true;
  last_cycle_ = cycle;
  last_receive_s_ = receive_time_s;
  return fade;
}

void RsiSession::answer_values(const std::array<double, kRsiAxes>& offset_rad,
                               std::array<double, kRsiAxes>* values_deg) noexcept {
  for (int a = 0; a < kRsiAxes; ++a) {
    const auto i = std::size_t(a);
    correction_rad_[i] = offset_rad[i];
    const double absolute_deg = offset_rad[i] * kDegPerRad;
    if (options_.mode == RsiCorrectionMode::kAbsolute) {
      (*values_deg)[i] = absolute_deg;
    } else {
      // The largest written value within the rate limit's step (rounded towards zero).
      const double step_deg = std::floor(precontrol_.options().rate_limit_rad_s[i] *
                                         options_.cycle_s * kDegPerRad * 1e6) /
                              1e6;
      const double increment =
          std::clamp(rsi_written_value(absolute_deg - sent_sum_deg_[i]), -step_deg, step_deg);
      sent_sum_deg_[i] += increment;
      (*values_deg)[i] = increment;
    }
  }
}

bool RsiSession::precontrol_input(const std::array<double, kRsiAxes>& setpoint_rad,
                                  PathSample* input) noexcept {
  input->q_rad = setpoint_rad;
  input->payload_kg = options_.payload_kg;
  if (!path_) return true;
  const bool on_path = path_->step(setpoint_rad, advanced_, input);
  // A path without payloads: the session's.
  if (on_path && input->payload_kg == 0.0) input->payload_kg = options_.payload_kg;
  return on_path;
}

int RsiSession::handle(std::string_view datagram, double receive_time_s, char* answer,
                       int capacity) noexcept {
  const RsiParseError error = parse_rsi_robot_datagram(datagram, &datagram_);
  if (error != RsiParseError::kNone) {
    record(0, SessionFault::kMalformed, int(error), 0.0);
    pending_fault_ = true;
    return refuse_datagram();
  }
  const std::uint64_t cycle = datagram_.ipoc / options_.ipoc_per_cycle;
  bool fade = judge(datagram_, receive_time_s);
  std::array<double, kRsiAxes> values_deg{};
  if (in_order_) {
    std::array<double, ident::kPrecontrolJoints> q_rad{};
    for (int a = 0; a < kRsiAxes; ++a)
      q_rad[std::size_t(a)] = datagram_.setpoint_deg[std::size_t(a)] / kDegPerRad;
    PathSample input;
    if (!precontrol_input(q_rad, &input)) {
      record(datagram_.ipoc, SessionFault::kOffPath, 0, 0.0);
      fade = true;
    }
    if (fade) precontrol_.fault(cycle, 0.0);
    const ident::PrecontrolOutput out =
        precontrol_.needs_model_torque()
            ? precontrol_.cycle(input.q_rad, input.payload_kg, input.torque_nm, cycle)
            : precontrol_.cycle(input.q_rad, input.payload_kg, cycle);
    state_ = out.state;
    answer_values(out.offset_rad, &values_deg);
  } else if (options_.mode == RsiCorrectionMode::kAbsolute) {
    // The correction held: no precontrol step for a datagram out of order.
    for (int a = 0; a < kRsiAxes; ++a)
      values_deg[std::size_t(a)] = correction_rad_[std::size_t(a)] * kDegPerRad;
  }  // increment mode out of order: zero increments
  return counted_answer(
      write_rsi_answer(options_.sensor_type, values_deg, datagram_.ipoc, answer, capacity));
}

}  // namespace imscal::online
