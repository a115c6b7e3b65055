#include "ident/precontrol.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "ident/arx_step_kernel.hpp"
#include "ident/cell_blending.hpp"

namespace imscal::ident {
namespace {

int round_up(int n, int multiple) {
  return (n + multiple - 1) / multiple * multiple;
}

// Pushes `value` as the newest entry of a doubled ring of `ring` entries (newest first).
template <std::size_t N>
void push_newest(std::array<double, N>& buffer, int& pos, int ring, double value) {
  pos = (pos - 1) & (ring - 1);
  buffer[pos] = value;
  buffer[pos + ring] = value;
}

double default_if_zero(double value, double fallback) {
  return value > 0.0 ? value : fallback;
}

}  // namespace

const char* to_string(PrecontrolState state) {
  switch (state) {
    case PrecontrolState::kActive:
      return "active";
    case PrecontrolState::kFadingOut:
      return "fading_out";
    case PrecontrolState::kInactive:
      return "inactive";
    case PrecontrolState::kEngaging:
      return "engaging";
  }
  return "?";
}

const char* to_string(PrecontrolCause cause) {
  switch (cause) {
    case PrecontrolCause::kNone:
      return "none";
    case PrecontrolCause::kOffsetTolerance:
      return "offset above tolerance";
    case PrecontrolCause::kRateTolerance:
      return "offset rate above tolerance";
    case PrecontrolCause::kInvalidInput:
      return "NaN or Inf input";
    case PrecontrolCause::kLostCycles:
      return "lost control cycles";
    case PrecontrolCause::kOutsideTable:
      return "operating point outside the table";
    case PrecontrolCause::kReactivated:
      return "re-activated";
    case PrecontrolCause::kMissingTorque:
      return "model torque missing";
    case PrecontrolCause::kInputJump:
      return "jump of the desired value";
    case PrecontrolCause::kCallerFault:
      return "fault reported by the caller";
    case PrecontrolCause::kEngaging:
      return "engaging";
    case PrecontrolCause::kEngaged:
      return "engaged";
  }
  return "?";
}

bool Precontrol::create(const ParameterTable& table, const std::string& robot,
                        const PrecontrolOptions& options, Precontrol* out, std::string* why) {
  auto refuse = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  if (table.robot != robot) {
    return refuse("the parameter table is for robot '" + table.robot + "', not '" + robot + "'");
  }
  if (table.joints.size() != kPrecontrolJoints) return refuse("the table must have 6 joints");
  const double T = table.sample_time_s, c = options.caller_cycle_s;
  if (!(T > 0.0) || !(c > 0.0)) return refuse("cycle times must be positive");
  Precontrol p;
  p.options_ = options;
  p.model_sample_s_ = T;
  if (table.extra_inputs.size() > std::size_t(kArxStepMaxExtras))
    return refuse("at most " + std::to_string(kArxStepMaxExtras) + " further inputs supported");
  p.extra_count_ = static_cast<int>(table.extra_inputs.size());
  std::copy(table.extra_inputs.begin(), table.extra_inputs.end(), p.inputs_.begin());
  p.needs_torque_ = has_input(table.extra_inputs, TableInput::kModelTorque);
  if (const std::string problem = exogenous_inputs_problem(table.extra_inputs); !problem.empty())
    return refuse(problem);
  if (!(table.direction_speed_scale_rad_s > 0.0)) return refuse("direction scale must be > 0");
  const double up = c / T, down = T / c;
  if (std::abs(up - std::round(up)) < 1e-9 * up && std::round(up) >= 1 && std::round(up) <= 8) {
    p.steps_per_call_ = static_cast<int>(std::round(up));
  } else if (std::abs(down - std::round(down)) < 1e-9 * down && std::round(down) <= 8) {
    p.calls_per_step_ = static_cast<int>(std::round(down));
  } else {
    return refuse("caller cycle " + std::to_string(c) +
                  " s is neither 1..8 times nor 1/1..1/8 of "
                  "the table's " +
                  std::to_string(T) + " s");
  }
  for (int j = 0; j < kPrecontrolJoints; ++j) {
    const JointParameters& source = table.joints[j];
    const double envelope = kEnvelopeTolerance * source.offset_envelope_rad;
    const double rate_envelope = kEnvelopeRateTolerance * source.offset_rate_envelope_rad_s;
    const double rate_limit = kEnvelopeRateLimit * source.offset_rate_envelope_rad_s;
    p.options_.offset_tolerance_rad[j] =
        default_if_zero(options.offset_tolerance_rad[j], default_if_zero(envelope, 5e-3));
    p.options_.rate_tolerance_rad_s[j] =
        default_if_zero(options.rate_tolerance_rad_s[j], default_if_zero(rate_envelope, 0.5));
    p.options_.rate_limit_rad_s[j] =
        default_if_zero(options.rate_limit_rad_s[j], default_if_zero(rate_limit, 0.2));
    JointModel& joint = p.joints_[j];
    const std::string name = "joint " + source.name + ": ";
    if (source.cells.empty() || source.cells.size() > kMaxPrecontrolCells) {
      return refuse(name + "1.." + std::to_string(kMaxPrecontrolCells) + " cells supported");
    }
    if (source.dimensions.empty() || source.dimensions.size() > 4) {
      return refuse(name + "1..4 operating-point dimensions supported");
    }
    joint.cells = static_cast<int>(source.cells.size());
    joint.dims = static_cast<int>(source.dimensions.size());
    int expected_cells = 1;
    for (int d = 0; d < joint.dims; ++d) {
      const CellDimension& dim = source.dimensions[d];
      const std::vector<double> centres = dim.centres();
      if (centres.empty() || centres.size() > kMaxPrecontrolCells) return refuse(name + "bad grid");
      joint.quantity[d] = dim.quantity;
      joint.centre_count[d] = static_cast<int>(centres.size());
      std::copy(centres.begin(), centres.end(), joint.centres[d].begin());
      joint.lower[d] = dim.bounds.front();
      joint.upper[d] = dim.bounds.back();
      expected_cells *= static_cast<int>(centres.size());
    }
    if (expected_cells != joint.cells) return refuse(name + "cell count does not match the grid");
    if (!std::isfinite(source.backlash_l_rad)) return refuse(name + "backlash is not finite");
    joint.backlash_l_rad = source.backlash_l_rad;
    if (source.backlash_lag_samples >= static_cast<std::size_t>(kSpeedRing)) {
      return refuse(name + "backlash lag of " + std::to_string(source.backlash_lag_samples) +
                    " samples exceeds the supported " + std::to_string(kSpeedRing - 1));
    }
    joint.backlash_lag = static_cast<int>(source.backlash_lag_samples);
    joint.exogenous = exogenous_parameters(table, source);
    if (const std::string problem =
            exogenous_parameters_problem(table.extra_inputs, joint.exogenous);
        !problem.empty())
      return refuse(name + problem);
    for (int k = 0; k < joint.cells; ++k) {
      const CellParameters& cell = source.cells[k];
      ArxCellCoefficients& model = joint.model[k];
      const ArxStructure& structure = cell.structure;
      if (structure.extra_inputs != p.extra_count_ ||
          cell.c.size() != std::size_t(structure.extra_coefficient_count())) {
        return refuse(name + "cell " + std::to_string(k) + ": " +
                      std::to_string(structure.extra_inputs) +
                      " further inputs, the table declares " + std::to_string(p.extra_count_));
      }
      bool in_range = structure.na >= 0 && structure.na <= kMaxPrecontrolOrder &&
                      structure.nb >= 1 && structure.nb <= kMaxPrecontrolOrder &&
                      structure.dead_time >= 0 && structure.dead_time <= kMaxPrecontrolDeadTime &&
                      static_cast<int>(cell.a.size()) == structure.na &&
                      static_cast<int>(cell.b.size()) == structure.nb;
      for (int e = 0; e < p.extra_count_; ++e) {
        const int nx = structure.nx[std::size_t(e)];
        in_range = in_range && nx >= 1 && nx <= kMaxPrecontrolOrder;
      }
      if (!in_range) {
        return refuse(name + "cell " + std::to_string(k) + ": order or dead time out of range");
      }
      // Each sum over its own length (zeros past na, nb, nx_e up to the next kArxStepLanes).
      model.dead_time = structure.dead_time;
      model.a_terms = round_up(structure.na, kArxStepLanes);
      model.b_terms = round_up(structure.nb, kArxStepLanes);
      std::copy(cell.a.begin(), cell.a.end(), model.a.begin());
      std::copy(cell.b.begin(), cell.b.end(), model.b.begin());
      for (int e = 0; e < p.extra_count_; ++e) {
        const int nx = structure.nx[std::size_t(e)];
        model.c_terms[std::size_t(e)] = round_up(nx, kArxStepLanes);
        for (int i = 0; i < nx; ++i)
          model.c[e][i] = cell.c[std::size_t(structure.extra_offset(e) + i)];
      }
      auto all_finite = [](const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
      };
      const bool finite = all_finite(cell.a) && all_finite(cell.b) && all_finite(cell.c);
      if (!finite) return refuse(name + "cell " + std::to_string(k) + ": NaN/Inf parameter");
    }
  }
  // As exp(-w dt) with w = 1 / τ, the smoother's own expression.
  p.smoother_decay_ = std::exp(-(1.0 / options.smoothing_time_constant_s) * options.caller_cycle_s);
  *out = p;
  return true;
}

void Precontrol::log(std::uint64_t cycle, int joint, PrecontrolCause cause, double value) noexcept {
  if (event_count_ == kPrecontrolEventCapacity) {
    ++dropped_events_;
    event_head_ = (event_head_ + 1) % kPrecontrolEventCapacity;
    --event_count_;
  }
  events_[(event_head_ + event_count_) % kPrecontrolEventCapacity] =
      PrecontrolEvent{cycle, static_cast<std::int8_t>(joint), cause, value};
  ++event_count_;
}

int Precontrol::read_events(PrecontrolEvent* out, int capacity) noexcept {
  const int n = std::min(capacity, event_count_);
  for (int i = 0; i < n; ++i) out[i] = events_[(event_head_ + i) % kPrecontrolEventCapacity];
  event_head_ = (event_head_ + n) % kPrecontrolEventCapacity;
  event_count_ -= n;
  return n;
}

std::array<double, kArxStepMaxExtras> Precontrol::extra_values(JointModel& joint, double x,
                                                               double speed,
                                                               double torque) const noexcept {
  std::array<double, kArxStepMaxExtras> value{};
  exogenous_values(std::span(inputs_.data(), std::size_t(extra_count_)), joint.exogenous,
                   ExogenousSample{x, speed, torque}, joint.exogenous_filter, value.data());
  return value;
}

void Precontrol::restart_models(const std::array<double, kPrecontrolJoints>& q,
                                const std::array<double, kPrecontrolJoints>& torque) noexcept {
  // At rest the robot stands where it was told: past inputs all equal q_d (and the torque of
  // that pose, direction 0), every model at its steady state for them,
  // q̂ = (B(1) q_d + Σ C_e(1) x_e) / A(1): q_d for a single-input joint-error model, q_d minus
  // the static deflection of the pose for a model with the torque input.
  for (int j = 0; j < kPrecontrolJoints; ++j) {
    JointModel& joint = joints_[j];
    joint.u.fill(q[j]);
    // The gear mode's filter settles at rest on this pose; model steps advance it from here.
    restart_exogenous_filter(joint.exogenous_filter, joint.exogenous, model_sample_s_);
    const std::array<double, kArxStepMaxExtras> x = extra_values(joint, q[j], 0.0, torque[j]);
    for (int e = 0; e < extra_count_; ++e) joint.x[e].fill(x[e]);
    for (int k = 0; k < joint.cells; ++k) {
      const ArxCellCoefficients& m = joint.model[k];
      // Over the sums' lengths: the entries past na, nb, nx_e are zeros.
      double a1 = 1.0, b1 = 0.0, steady_extra = 0.0;
      for (int i = 0; i < m.a_terms; ++i) a1 += m.a[i];
      for (int i = 0; i < m.b_terms; ++i) b1 += m.b[i];
      for (int e = 0; e < extra_count_; ++e)
        for (int i = 0; i < m.c_terms[e]; ++i) steady_extra += m.c[e][i] * x[e];
      // Near an integrator (A(1) ~ 0) the steady state is not defined: start at q_d.
      const double steady = std::abs(a1) > 1e-9 ? (b1 * q[j] + steady_extra) / a1 : q[j];
      joint.output_history[k].y.fill(steady);
    }
    joint.last_error = joint.previous_error = 0.0;
    joint.smooth = joint.output;
    joint.smooth_rate = 0.0;
    last_speed_[j] = 0.0;
    joint.speed_history.fill(0.0);
  }
  last_q_ = q;
  last_torque_ = torque;
  call_phase_ = 0;
}

void Precontrol::model_step(JointModel& joint, double q_desired, double speed, double acceleration,
                            double payload, double torque, bool& outside) noexcept {
  push_newest(joint.u, joint.u_pos, kInputRing, q_desired);
  const double* u = joint.u.data() + joint.u_pos;  // u[i] = q_d(k - i)
  const std::array<double, kArxStepMaxExtras> x = extra_values(joint, q_desired, speed, torque);
  for (int e = 0; e < extra_count_; ++e) {
    joint.x[e][joint.u_pos] = x[e];
    joint.x[e][joint.u_pos + kInputRing] = x[e];
  }

  std::array<double, 4> point{};
  std::array<std::span<const double>, 4> centres{};
  for (int d = 0; d < joint.dims; ++d) {
    switch (joint.quantity[d]) {
      case OperatingQuantity::kSpeed:
        point[d] = std::abs(speed);
        break;
      case OperatingQuantity::kPayload:
        point[d] = payload;
        break;
      case OperatingQuantity::kPosition:
        point[d] = q_desired;
        break;
      case OperatingQuantity::kAcceleration:
        point[d] = std::abs(acceleration);
        break;
    }
    outside = outside || point[d] < joint.lower[d] || point[d] > joint.upper[d];
    centres[d] = std::span<const double>(joint.centres[d].data(), joint.centre_count[d]);
  }
  const CellBlend blend = blend_cells(std::span(centres.data(), joint.dims),
                                      std::span<const double>(point.data(), joint.dims));
  // Every cell model advances, in or out of the blend: a cell entering the blend needs its own
  // free-run state (see the header); the blend weights pick their errors.
  ArxInputWindows windows;
  windows.u = u;
  windows.extra_count = extra_count_;
  for (int e = 0; e < extra_count_; ++e) windows.x[e] = joint.x[e].data() + joint.u_pos;
  std::array<const double*, kMaxPrecontrolCells> y_past;  // only the first `cells` are set
  for (int c = 0; c < joint.cells; ++c) {
    const OutputHistory& h = joint.output_history[c];
    y_past[c] = h.y.data() + h.pos;
  }
  std::array<double, kMaxPrecontrolCells> y, error;
  arx_free_run_steps(joint.model.data(), y_past.data(), joint.cells, windows, y.data());
  for (int c = 0; c < joint.cells; ++c) {
    OutputHistory& h = joint.output_history[c];
    push_newest(h.y, h.pos, kOutputRing, y[c]);
    error[c] = u[joint.model[c].dead_time] - y[c];
  }
  double blended = 0.0;
  for (int i = 0; i < blend.count; ++i) blended += blend.weight[i] * error[blend.cell[i]];
  joint.previous_error = joint.last_error;
  joint.last_error = blended;
}

void Precontrol::deactivate(std::uint64_t cycle, int joint, PrecontrolCause cause,
                            double value) noexcept {
  log(cycle, joint, cause, value);
  valid_for_s_ = 0.0;
  if (state_ != PrecontrolState::kActive && state_ != PrecontrolState::kEngaging) return;
  state_ = PrecontrolState::kFadingOut;
  fade_elapsed_s_ = 0.0;
  for (int j = 0; j < kPrecontrolJoints; ++j) fade_from_[j] = joints_[j].output;
}

void Precontrol::reactivate() noexcept {
  log(last_cycle_, -1, PrecontrolCause::kReactivated, 0.0);
  state_ = PrecontrolState::kActive;
  if (started_) restart_models(last_q_, last_torque_);
}

void Precontrol::fault(std::uint64_t cycle_counter, double code) noexcept {
  deactivate(cycle_counter, -1, PrecontrolCause::kCallerFault, code);
}

void Precontrol::start_engaging(std::uint64_t cycle_counter) noexcept {
  log(cycle_counter, -1, PrecontrolCause::kEngaging, 0.0);
  state_ = PrecontrolState::kEngaging;
  engage_elapsed_s_ = 0.0;
  valid_for_s_ = 0.0;
}

PrecontrolOutput Precontrol::cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                                   double payload_kg, std::uint64_t cycle_counter) noexcept {
  return run_cycle(q_desired_rad, payload_kg, nullptr, cycle_counter);
}

PrecontrolOutput Precontrol::cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                                   double payload_kg,
                                   const std::array<double, kPrecontrolJoints>& model_torque_nm,
                                   std::uint64_t cycle_counter) noexcept {
  return run_cycle(q_desired_rad, payload_kg, &model_torque_nm, cycle_counter);
}

bool Precontrol::accept_input(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                              double payload_kg,
                              const std::array<double, kPrecontrolJoints>* model_torque_nm,
                              std::uint64_t cycle_counter,
                              std::array<double, kPrecontrolJoints>& torque) noexcept {
  bool valid = std::isfinite(payload_kg);
  for (double q : q_desired_rad) valid = valid && std::isfinite(q);
  if (model_torque_nm != nullptr) {
    torque = *model_torque_nm;
    for (double t : torque) valid = valid && std::isfinite(t);
  }
  if (needs_model_torque() && model_torque_nm == nullptr) {
    // A table whose models need the torque cannot run without it: off, as for bad input.
    if (state_ == PrecontrolState::kActive)
      deactivate(cycle_counter, -1, PrecontrolCause::kMissingTorque, 0.0);
    valid = false;
  } else if (!valid) {
    deactivate(cycle_counter, -1, PrecontrolCause::kInvalidInput, 0.0);
  } else if (!started_) {
    restart_models(q_desired_rad, torque);
    started_ = true;
    if (options_.auto_engage) start_engaging(cycle_counter);
  } else if (cycle_counter != last_cycle_ + 1) {
    const double lost = static_cast<double>(cycle_counter - last_cycle_) - 1.0;
    if (cycle_counter <= last_cycle_ || lost > options_.max_lost_cycles) {
      deactivate(cycle_counter, -1, PrecontrolCause::kLostCycles, lost);
      restart_models(q_desired_rad, torque);
    } else {  // bridge: the model sees the last input held over the lost cycles
      bool ignored = false;
      for (int k = 0; k < static_cast<int>(lost) * steps_per_call_; ++k) {
        for (int j = 0; j < kPrecontrolJoints; ++j) {
          model_step(joints_[j], last_q_[j], 0.0, 0.0, last_payload_, last_torque_[j], ignored);
        }
      }
    }
  } else if (options_.max_input_speed_rad_s > 0.0) {
    for (int j = 0; j < kPrecontrolJoints; ++j) {
      const double speed = (q_desired_rad[j] - last_q_[j]) / options_.caller_cycle_s;
      if (std::abs(speed) > options_.max_input_speed_rad_s) {
        deactivate(cycle_counter, j, PrecontrolCause::kInputJump, speed);
        restart_models(q_desired_rad, torque);
        break;
      }
    }
  }
  if (valid) last_cycle_ = cycle_counter;
  return valid;
}

double Precontrol::engagement_gain(bool valid, std::uint64_t cycle_counter) noexcept {
  if (!options_.auto_engage) return 1.0;
  const double dt = options_.caller_cycle_s;
  if (state_ == PrecontrolState::kInactive) {
    valid_for_s_ = valid ? valid_for_s_ + dt : 0.0;
    // The models restart from the input of this cycle (accept_input kept it in last_q_ only
    // for valid input, which this is).
    if (valid && valid_for_s_ >= options_.reengage_after_s) start_engaging(cycle_counter);
  }
  if (state_ != PrecontrolState::kEngaging) return 1.0;
  if (valid) engage_elapsed_s_ += dt;
  const double ramp_s = engage_elapsed_s_ - options_.engage_settle_s;
  if (ramp_s <= 0.0) return 0.0;
  if (ramp_s >= options_.fade_out_s) {
    state_ = PrecontrolState::kActive;
    log(cycle_counter, -1, PrecontrolCause::kEngaged, 0.0);
    return 1.0;
  }
  return 0.5 * (1.0 - std::cos(M_PI * ramp_s / options_.fade_out_s));
}

PrecontrolOutput Precontrol::run_cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                                       double payload_kg,
                                       const std::array<double, kPrecontrolJoints>* model_torque_nm,
                                       std::uint64_t cycle_counter) noexcept {
  const double dt = options_.caller_cycle_s;
  PrecontrolOutput out;
  std::array<double, kPrecontrolJoints> torque{};
  const bool valid =
      accept_input(q_desired_rad, payload_kg, model_torque_nm, cycle_counter, torque);
  const bool was_inactive = state_ == PrecontrolState::kInactive;
  const double gain = engagement_gain(valid, cycle_counter);
  if (was_inactive && state_ == PrecontrolState::kEngaging) restart_models(q_desired_rad, torque);
  // While settling the models' restart transient decays: the supervisor does not judge it.
  const bool supervise =
      state_ == PrecontrolState::kActive || engage_elapsed_s_ > options_.engage_settle_s;

  bool outside = false;
  if (valid && (state_ == PrecontrolState::kActive || state_ == PrecontrolState::kEngaging)) {
    // Model steps at the table's sample time (several per call, or one every few calls).
    ++call_phase_;
    const bool step_now = call_phase_ >= calls_per_step_;
    for (int j = 0; j < kPrecontrolJoints; ++j) {
      JointModel& joint = joints_[j];
      const double speed = (q_desired_rad[j] - last_q_[j]) / dt;
      const double acceleration = (speed - last_speed_[j]) / dt;
      if (step_now) {
        for (int s = 1; s <= steps_per_call_; ++s) {
          const double f = static_cast<double>(s) / steps_per_call_;
          model_step(joint, last_q_[j] + f * (q_desired_rad[j] - last_q_[j]), speed, acceleration,
                     payload_kg, last_torque_[j] + f * (torque[j] - last_torque_[j]), outside);
        }
      }
      const double phase =
          static_cast<double>(step_now ? calls_per_step_ : call_phase_) / calls_per_step_;
      const double error =
          calls_per_step_ == 1
              ? joint.last_error
              : joint.previous_error + phase * (joint.last_error - joint.previous_error);
      joint.speed_pos = (joint.speed_pos + 1) & (kSpeedRing - 1);
      joint.speed_history[joint.speed_pos] = speed;
      const double direction_speed =
          joint.speed_history[(joint.speed_pos - joint.backlash_lag) & (kSpeedRing - 1)];
      const double raw =
          error + joint.backlash_l_rad *
                      std::tanh(direction_speed / options_.backlash_velocity_scale_rad_s);
      // Written as !(|x| <= tol) so that a NaN (an overflowing model) deactivates too.
      if (supervise && !(std::abs(raw) <= options_.offset_tolerance_rad[j])) {
        deactivate(cycle_counter, j, PrecontrolCause::kOffsetTolerance, raw);
        break;
      }
      // Critically damped smoother, exact over dt with the raw value held:
      // e = x - r, e(t) = (e0 + (v0 + w e0) t) exp(-w t), v(t) = (v0 - w (v0 + w e0) t) exp(-w t).
      const double w = 1.0 / options_.smoothing_time_constant_s;
      const double e0 = joint.smooth - raw, v0 = joint.smooth_rate;
      const double decay = smoother_decay_;  // exp(-w dt)
      joint.smooth = raw + (e0 + (v0 + w * e0) * dt) * decay;
      joint.smooth_rate = (v0 - w * (v0 + w * e0) * dt) * decay;
      if (supervise && !(std::abs(joint.smooth_rate) <= options_.rate_tolerance_rad_s[j])) {
        deactivate(cycle_counter, j, PrecontrolCause::kRateTolerance, joint.smooth_rate);
        break;
      }
      last_speed_[j] = speed;
    }
    if (step_now) call_phase_ = 0;
    if (outside && !was_outside_) log(cycle_counter, -1, PrecontrolCause::kOutsideTable, 0.0);
    was_outside_ = outside;
  }
  if (valid) {
    last_q_ = q_desired_rad;  // also while inactive: a re-activation restarts from here
    last_torque_ = torque;
    last_payload_ = payload_kg;
  }
  compose_output(gain, out);
  return out;
}

void Precontrol::compose_output(double engagement_gain, PrecontrolOutput& out) noexcept {
  // The smoothed offsets, the fade-in or the fade-out ramp; never a step above the rate limit.
  const double dt = options_.caller_cycle_s;
  double fade = 0.0;
  if (state_ == PrecontrolState::kFadingOut) {
    fade_elapsed_s_ += dt;
    if (fade_elapsed_s_ >= options_.fade_out_s) {
      state_ = PrecontrolState::kInactive;
      valid_for_s_ = 0.0;
    } else {
      fade = 0.5 * (1.0 + std::cos(M_PI * fade_elapsed_s_ / options_.fade_out_s));
    }
  }
  for (int j = 0; j < kPrecontrolJoints; ++j) {
    JointModel& joint = joints_[j];
    double target = 0.0;
    if (state_ == PrecontrolState::kActive) target = joint.smooth;
    if (state_ == PrecontrolState::kEngaging) target = joint.smooth * engagement_gain;
    if (state_ == PrecontrolState::kFadingOut) target = fade_from_[j] * fade;
    const double step = options_.rate_limit_rad_s[j] * dt;
    joint.output += std::clamp(target - joint.output, -step, step);
    out.offset_rad[j] = joint.output;
  }
  out.state = state_;
  out.outside_table = was_outside_;
}

}  // namespace imscal::ident
