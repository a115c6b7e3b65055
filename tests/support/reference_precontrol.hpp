#pragma once
// The precontrol cycle as it was before its speed work (ident/precontrol.* at commit
// ef0e005): every cell's ARX model advances in every cycle, whether or not it is in the blend,
// each sum an Eigen dot product over exactly its own coefficients. Kept (renamed) as the reference
// that the faster runtime is compared with: by tests/ident/test_precontrol*.cpp (same offsets
// within a stated tolerance) and by bench/bench_precontrol.cpp (before/after cycle times in the
// same run). Not for production use.
// Extended by the further inputs of the multi-input models: their values from the one definition
// of ident/exogenous_inputs.hpp (exogenous_values, as the runtime and the identification), their
// sums written here again: Σ_j c_e,j x_e(k-d-j) over the nx_e coefficients of input e, in the
// table order; started at the steady state of the pose's torque; lost cycles bridged with the
// last torque.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>

#include "ident/cell_blending.hpp"
#include "ident/parameter_table.hpp"
#include "ident/precontrol.hpp"

namespace imscal::test_support::reference_precontrol {
using namespace imscal::ident;

constexpr int kOutputRing = kMaxPrecontrolOrder;
static_assert((kOutputRing & (kOutputRing - 1)) == 0);

// Σ a[i] b[i] by Eigen's vectorised dot product (SIMD packets, several partial sums): a plain
// loop is one chain of n dependent multiply-adds, latency bound. The rounding differs from a
// plain loop by a few ulp.
inline double dot(const double* a, const double* b, int n) {
  if (n == 0) return 0.0;
  return Eigen::Map<const Eigen::VectorXd>(a, n).dot(Eigen::Map<const Eigen::VectorXd>(b, n));
}

// Pushes `value` as the newest entry of a doubled ring of `ring` entries (newest first).
template <std::size_t N>
inline void push_newest(std::array<double, N>& buffer, int& pos, int ring, double value) {
  pos = (pos - 1) & (ring - 1);
  buffer[pos] = value;
  buffer[pos + ring] = value;
}

inline double default_if_zero(double value, double fallback) {
  return value > 0.0 ? value : fallback;
}

class AllCellsPrecontrol {
 public:
  // Refuses (returns false with the reason in *why) a table for another robot, with another
  // joint count, sizes beyond the fixed capacity, non-finite parameters, or a caller cycle that
  // is not m·T or T/m. On success *out is ready (the only allocation-free object afterwards).
  static bool create(const ParameterTable& table, const std::string& robot,
                     const PrecontrolOptions& options, AllCellsPrecontrol* out, std::string* why);

  // One control cycle. cycle_counter: the caller's cycle number (consecutive normally).
  PrecontrolOutput cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                         double payload_kg, std::uint64_t cycle_counter) noexcept {
    return run_cycle(q_desired_rad, payload_kg, nullptr, cycle_counter);
  }
  // The same with the model torques [N m], for tables with further inputs.
  PrecontrolOutput cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                         double payload_kg,
                         const std::array<double, kPrecontrolJoints>& model_torque_nm,
                         std::uint64_t cycle_counter) noexcept {
    return run_cycle(q_desired_rad, payload_kg, &model_torque_nm, cycle_counter);
  }
  bool needs_model_torque() const noexcept { return needs_torque_; }

  // Explicit re-activation after a deactivation: the models restart from the current desired
  // values (at rest: zero error) and the offsets rise smoothly from zero.
  void reactivate() noexcept;

  PrecontrolState state() const noexcept { return state_; }
  // Events since the last call (oldest first), copied out; the ring keeps the newest
  // kPrecontrolEventCapacity and counts what it dropped.
  int read_events(PrecontrolEvent* out, int capacity) noexcept;
  std::uint64_t dropped_events() const noexcept { return dropped_events_; }

 private:
  // Histories are rings stored twice (each value written at i and i + ring): the newest-first
  // window of any length up to the ring size is then contiguous, so the model's dot products
  // run over plain arrays (vectorised) without index wrapping.
  static constexpr int kInputRing = 128;  // power of two >= nb + d
  static_assert(kInputRing >= kMaxPrecontrolOrder + kMaxPrecontrolDeadTime);
  static constexpr int kSpeedRing = 128;  // > the largest backlash lag accepted [cycles]
  static constexpr int kMaxExtras = kMaxExtraInputs;
  struct CellModel {
    int na = 0, nb = 0, d = 0;
    std::array<int, kMaxExtras> nx{};
    std::array<double, kMaxPrecontrolOrder> a{};
    std::array<double, kMaxPrecontrolOrder> b{};
    std::array<std::array<double, kMaxPrecontrolOrder>, kMaxExtras> c{};  // input after input
    std::array<double, 2 * kMaxPrecontrolOrder> y{};  // q̂ history, newest at y[y_pos]
    int y_pos = 0;
  };
  struct JointModel {
    int cells = 0;
    std::array<CellModel, kMaxPrecontrolCells> cell{};
    // Blending grid: per dimension the quantity and cell centres.
    int dims = 0;
    std::array<OperatingQuantity, 4> quantity{};
    std::array<std::array<double, kMaxPrecontrolCells>, 4> centres{};
    std::array<int, 4> centre_count{};
    std::array<double, 4> lower{}, upper{};  // grid bounds (outside: event)
    double backlash_l_rad = 0.0;
    ExogenousParameters exogenous;          // the constants of the further inputs
    ExogenousFilterState exogenous_filter;  // the gear mode's filter along the model steps
    // The identification's direction of motion is the desired velocity `backlash_lag` cycles
    // earlier (ident/backlash_identification.hpp): a ring of past speeds [rad/s].
    int backlash_lag = 0;
    std::array<double, kSpeedRing> speed_history{};
    int speed_pos = 0;
    // Input history q_d(k), q_d(k-1), ... (ring), newest at u_head.
    std::array<double, 2 * kInputRing> u{};  // q_d history, newest at u[u_pos]
    int u_pos = 0;
    std::array<std::array<double, 2 * kInputRing>, kMaxExtras> x{};  // x_e history, newest at u_pos
    double last_error = 0.0;      // blended Δq̂ of the last model step
    double previous_error = 0.0;  // the one before (for output interpolation at T/m cycles)
    double smooth = 0.0, smooth_rate = 0.0;  // smoother state
    double output = 0.0;                     // last offset handed out
  };

  void model_step(JointModel& joint, double q_desired, double speed, double acceleration,
                  double payload, double torque, bool& outside) noexcept;
  std::array<double, kMaxExtras> extra_values(JointModel& joint, double x, double speed,
                                              double torque) const noexcept;
  void restart_models(const std::array<double, kPrecontrolJoints>& q_desired,
                      const std::array<double, kPrecontrolJoints>& torque) noexcept;
  PrecontrolOutput run_cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                             double payload_kg,
                             const std::array<double, kPrecontrolJoints>* model_torque_nm,
                             std::uint64_t cycle_counter) noexcept;
  void deactivate(std::uint64_t cycle, int joint, PrecontrolCause cause, double value) noexcept;
  void log(std::uint64_t cycle, int joint, PrecontrolCause cause, double value) noexcept;

  PrecontrolOptions options_;
  double model_sample_s_ = 0.002;
  int steps_per_call_ = 1;  // caller cycle = steps · T
  int calls_per_step_ = 1;  // caller cycle = T / calls
  int call_phase_ = 0;
  std::array<JointModel, kPrecontrolJoints> joints_{};
  std::array<double, kPrecontrolJoints> last_q_{};
  std::array<double, kPrecontrolJoints> last_speed_{};
  std::array<double, kPrecontrolJoints> last_torque_{};
  int extra_count_ = 0;
  std::array<TableInput, kMaxExtras> inputs_{};  // the first extra_count_: table order
  bool needs_torque_ = false;
  double last_payload_ = 0.0;
  bool started_ = false;
  std::uint64_t last_cycle_ = 0;
  PrecontrolState state_ = PrecontrolState::kActive;
  double fade_elapsed_s_ = 0.0;
  std::array<double, kPrecontrolJoints> fade_from_{};
  bool was_outside_ = false;
  std::array<PrecontrolEvent, kPrecontrolEventCapacity> events_{};
  int event_head_ = 0, event_count_ = 0;
  std::uint64_t dropped_events_ = 0;
};

inline bool AllCellsPrecontrol::create(const ParameterTable& table, const std::string& robot,
                                       const PrecontrolOptions& options, AllCellsPrecontrol* out,
                                       std::string* why) {
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
  AllCellsPrecontrol p;
  p.options_ = options;
  p.model_sample_s_ = T;
  if (table.extra_inputs.size() > std::size_t(kMaxExtras)) return refuse("too many inputs");
  p.extra_count_ = static_cast<int>(table.extra_inputs.size());
  std::copy(table.extra_inputs.begin(), table.extra_inputs.end(), p.inputs_.begin());
  p.needs_torque_ = has_input(table.extra_inputs, TableInput::kModelTorque);
  if (!exogenous_inputs_problem(table.extra_inputs).empty()) return refuse("sign without torque");
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
    p.options_.offset_tolerance_rad[j] = default_if_zero(options.offset_tolerance_rad[j], 5e-3);
    p.options_.rate_tolerance_rad_s[j] = default_if_zero(options.rate_tolerance_rad_s[j], 0.5);
    p.options_.rate_limit_rad_s[j] = default_if_zero(options.rate_limit_rad_s[j], 0.2);
    const JointParameters& source = table.joints[j];
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
    for (int k = 0; k < joint.cells; ++k) {
      const CellParameters& cell = source.cells[k];
      CellModel& model = joint.cell[k];
      model.na = cell.structure.na;
      model.nb = cell.structure.nb;
      model.d = cell.structure.dead_time;
      if (model.na < 0 || model.na > kMaxPrecontrolOrder || model.nb < 1 ||
          model.nb > kMaxPrecontrolOrder || model.d < 0 || model.d > kMaxPrecontrolDeadTime ||
          static_cast<int>(cell.a.size()) != model.na ||
          static_cast<int>(cell.b.size()) != model.nb) {
        return refuse(name + "cell " + std::to_string(k) + ": order or dead time out of range");
      }
      for (int i = 0; i < model.na; ++i) model.a[i] = cell.a[i];
      for (int i = 0; i < model.nb; ++i) model.b[i] = cell.b[i];
      if (cell.structure.extra_inputs != p.extra_count_ ||
          cell.c.size() != std::size_t(cell.structure.extra_coefficient_count())) {
        return refuse(name + "further inputs differ from the table's");
      }
      for (int e = 0; e < p.extra_count_; ++e) {
        model.nx[e] = cell.structure.nx[std::size_t(e)];
        if (model.nx[e] < 1 || model.nx[e] > kMaxPrecontrolOrder) return refuse(name + "bad nx");
        for (int i = 0; i < model.nx[e]; ++i)
          model.c[e][i] = cell.c[std::size_t(cell.structure.extra_offset(e) + i)];
      }
      auto finite_values = [](const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
      };
      const bool finite = finite_values(cell.a) && finite_values(cell.b) && finite_values(cell.c);
      if (!finite) return refuse(name + "cell " + std::to_string(k) + ": NaN/Inf parameter");
    }
  }
  *out = p;
  return true;
}

inline void AllCellsPrecontrol::log(std::uint64_t cycle, int joint, PrecontrolCause cause,
                                    double value) noexcept {
  if (event_count_ == kPrecontrolEventCapacity) {
    ++dropped_events_;
    event_head_ = (event_head_ + 1) % kPrecontrolEventCapacity;
    --event_count_;
  }
  events_[(event_head_ + event_count_) % kPrecontrolEventCapacity] =
      PrecontrolEvent{cycle, static_cast<std::int8_t>(joint), cause, value};
  ++event_count_;
}

inline int AllCellsPrecontrol::read_events(PrecontrolEvent* out, int capacity) noexcept {
  const int n = std::min(capacity, event_count_);
  for (int i = 0; i < n; ++i) out[i] = events_[(event_head_ + i) % kPrecontrolEventCapacity];
  event_head_ = (event_head_ + n) % kPrecontrolEventCapacity;
  event_count_ -= n;
  return n;
}

inline std::array<double, AllCellsPrecontrol::kMaxExtras> AllCellsPrecontrol::extra_values(
    JointModel& joint, double x, double speed, double torque) const noexcept {
  std::array<double, kMaxExtras> value{};
  exogenous_values(std::span(inputs_.data(), std::size_t(extra_count_)), joint.exogenous,
                   ExogenousSample{x, speed, torque}, joint.exogenous_filter, value.data());
  return value;
}

inline void AllCellsPrecontrol::restart_models(
    const std::array<double, kPrecontrolJoints>& q,
    const std::array<double, kPrecontrolJoints>& torque) noexcept {
  // At rest the robot stands where it was told: past inputs all equal q_d (and the pose's
  // torque, direction 0), every model at its steady state (B(1) q_d + Σ_e C_e(1) x_e) / A(1)
  // (q_d itself near an integrator, A(1) ~ 0).
  for (int j = 0; j < kPrecontrolJoints; ++j) {
    JointModel& joint = joints_[j];
    joint.u.fill(q[j]);
    restart_exogenous_filter(joint.exogenous_filter, joint.exogenous, model_sample_s_);
    const std::array<double, kMaxExtras> x = extra_values(joint, q[j], 0.0, torque[j]);
    for (int e = 0; e < extra_count_; ++e) joint.x[e].fill(x[e]);
    for (int k = 0; k < joint.cells; ++k) {
      CellModel& m = joint.cell[k];
      double a1 = 1.0, b1 = 0.0, extra = 0.0;
      for (int i = 0; i < m.na; ++i) a1 += m.a[i];
      for (int i = 0; i < m.nb; ++i) b1 += m.b[i];
      for (int e = 0; e < extra_count_; ++e)
        for (int i = 0; i < m.nx[e]; ++i) extra += m.c[e][i] * x[e];
      m.y.fill(std::abs(a1) > 1e-9 ? (b1 * q[j] + extra) / a1 : q[j]);
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

inline void AllCellsPrecontrol::model_step(JointModel& joint, double q_desired, double speed,
                                           double acceleration, double payload, double torque,
                                           bool& outside) noexcept {
  push_newest(joint.u, joint.u_pos, kInputRing, q_desired);
  const double* u = joint.u.data() + joint.u_pos;  // u[i] = q_d(k - i)
  const std::array<double, kMaxExtras> x_now = extra_values(joint, q_desired, speed, torque);
  for (int e = 0; e < extra_count_; ++e) {
    joint.x[e][joint.u_pos] = x_now[e];
    joint.x[e][joint.u_pos + kInputRing] = x_now[e];
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
  // Every cell model advances (so a cell entering the blend has a settled state); the blend
  // weights pick their errors.
  std::array<double, kMaxPrecontrolCells> error{};
  for (int c = 0; c < joint.cells; ++c) {
    CellModel& m = joint.cell[c];
    const double* y_past = m.y.data() + m.y_pos;  // y_past[i] = q̂(k - 1 - i)
    double input = dot(m.b.data(), u + m.d, m.nb);
    for (int e = 0; e < extra_count_; ++e)
      input += dot(m.c[e].data(), joint.x[e].data() + joint.u_pos + m.d, m.nx[e]);
    const double y = input - dot(m.a.data(), y_past, m.na);
    push_newest(m.y, m.y_pos, kOutputRing, y);
    error[c] = u[m.d] - y;
  }
  double blended = 0.0;
  for (int i = 0; i < blend.count; ++i) blended += blend.weight[i] * error[blend.cell[i]];
  joint.previous_error = joint.last_error;
  joint.last_error = blended;
}

inline void AllCellsPrecontrol::deactivate(std::uint64_t cycle, int joint, PrecontrolCause cause,
                                           double value) noexcept {
  log(cycle, joint, cause, value);
  if (state_ != PrecontrolState::kActive) return;
  state_ = PrecontrolState::kFadingOut;
  fade_elapsed_s_ = 0.0;
  for (int j = 0; j < kPrecontrolJoints; ++j) fade_from_[j] = joints_[j].output;
}

inline void AllCellsPrecontrol::reactivate() noexcept {
  log(last_cycle_, -1, PrecontrolCause::kReactivated, 0.0);
  state_ = PrecontrolState::kActive;
  if (started_) restart_models(last_q_, last_torque_);
}

inline PrecontrolOutput AllCellsPrecontrol::run_cycle(
    const std::array<double, kPrecontrolJoints>& q_desired_rad, double payload_kg,
    const std::array<double, kPrecontrolJoints>* model_torque_nm,
    std::uint64_t cycle_counter) noexcept {
  const double dt = options_.caller_cycle_s;
  PrecontrolOutput out;
  bool valid = std::isfinite(payload_kg);
  for (double q : q_desired_rad) valid = valid && std::isfinite(q);
  std::array<double, kPrecontrolJoints> torque{};
  if (model_torque_nm != nullptr) {
    torque = *model_torque_nm;
    for (double t : torque) valid = valid && std::isfinite(t);
  }
  if (needs_model_torque() && model_torque_nm == nullptr) {
    if (state_ == PrecontrolState::kActive)
      deactivate(cycle_counter, -1, PrecontrolCause::kMissingTorque, 0.0);
    valid = false;
  } else if (!valid) {
    deactivate(cycle_counter, -1, PrecontrolCause::kInvalidInput, 0.0);
  } else if (!started_) {
    restart_models(q_desired_rad, torque);
    started_ = true;
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
  }
  if (valid) last_cycle_ = cycle_counter;

  bool outside = false;
  if (valid && state_ == PrecontrolState::kActive) {
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
      if (std::abs(raw) > options_.offset_tolerance_rad[j]) {
        deactivate(cycle_counter, j, PrecontrolCause::kOffsetTolerance, raw);
        break;
      }
      // Critically damped smoother, exact over dt with the raw value held:
      // e = x - r, e(t) = (e0 + (v0 + w e0) t) exp(-w t), v(t) = (v0 - w (v0 + w e0) t) exp(-w t).
      const double w = 1.0 / options_.smoothing_time_constant_s;
      const double e0 = joint.smooth - raw, v0 = joint.smooth_rate;
      const double decay = std::exp(-w * dt);
      joint.smooth = raw + (e0 + (v0 + w * e0) * dt) * decay;
      joint.smooth_rate = (v0 - w * (v0 + w * e0) * dt) * decay;
      if (std::abs(joint.smooth_rate) > options_.rate_tolerance_rad_s[j]) {
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

  // Output: the smoothed offsets, or the fade-out ramp; never a step above the rate limit.
  double fade = 0.0;
  if (state_ == PrecontrolState::kFadingOut) {
    fade_elapsed_s_ += dt;
    if (fade_elapsed_s_ >= options_.fade_out_s) {
      state_ = PrecontrolState::kInactive;
    } else {
      fade = 0.5 * (1.0 + std::cos(M_PI * fade_elapsed_s_ / options_.fade_out_s));
    }
  }
  for (int j = 0; j < kPrecontrolJoints; ++j) {
    JointModel& joint = joints_[j];
    double target = 0.0;
    if (state_ == PrecontrolState::kActive) target = joint.smooth;
    if (state_ == PrecontrolState::kFadingOut) target = fade_from_[j] * fade;
    const double step = options_.rate_limit_rad_s[j] * dt;
    joint.output += std::clamp(target - joint.output, -step, step);
    out.offset_rad[j] = joint.output;
  }
  out.state = state_;
  out.outside_table = was_outside_;
  return out;
}

}  // namespace imscal::test_support::reference_precontrol

namespace imscal::test_support {
using reference_precontrol::AllCellsPrecontrol;
}  // namespace imscal::test_support
