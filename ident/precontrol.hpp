#pragma once
// The online error compensation (paper, section 3.4): linked by a controller integrator,
// constructed once from a parameter table (ident/parameter_table.hpp), then called once per
// control cycle with the desired joint angles and the payload. It returns per joint the offset
// Δq to add to the desired angle, and a status.
//
// Per joint and cycle:
//   1. the cells are blended by the operating point (ident/cell_blending.hpp): continuous across
//      cell boundaries; outside the table the outermost cells are used and an event is logged;
//   2. every cell's ARX model (paper eq. 2) runs on the desired angle (free run: its own past
//      outputs), giving Δq̂_c(k) = q_d(k-d) - q̂_c(k) (as ArxModel::predict_joint_error); the
//      blend is Σ w_c Δq̂_c. The input history is one ring per joint (q_d is the same for all
//      cells); the output history is per cell. Cells outside the blend run too, on purpose:
//      a cell entering the blend needs its own free-run state, which depends on the
//      whole past input through its own poles. Starting it instead from the blended past
//      (q̂_c(k-i) = q_d(k-i-d_c) - Δq̂(k-i)) or from rest excites the cell's transient; in the
//      companion form of an order-32 model (|a_i| up to ~1e8) that transient reached 2.3 rad in
//      bench/bench_precontrol.cpp's table within a few cycles, so "only the blended cells" was
//      rejected. The cycle is made fast instead by the padded SIMD sums of
//      ident/arx_step_kernel.hpp, each over its own length (a one-tap input costs one block of
//      8 products, not max(na, nb, nx) of them), with the same outputs as before within a few
//      ulp (tests/ident/test_precontrol*.cpp compare with the all-cells reference). Measured and
//      not taken (bench/bench_precontrol.cpp's 6-cell grid with the further inputs, kernel alone):
//      the input sums of all cells of a joint as one matrix-vector product over the shared
//      histories (cells in the SIMD lanes) saved ~13 % of the kernel (~6 % of the cycle), at the
//      price of coefficient matrices sized for the largest table accepted (16 cells, 64 taps,
//      dead times up to 64 apart: ~380 kB more state) and a second code path for one-cell
//      tables; 8-wide AVX-512 registers saved nothing (the sums are not bound by their width);
//   3. the backlash term of eq. 3, l · tanh(q̇_d(k - lag) / v_b) with the table's lag: ±l when
//      moving, a smooth transition through zero velocity instead of a jump at reversals (no
//      chattering);
//   4. a critically damped second-order smoother (time constant τ) makes offset and its rate
//      continuous; the output change per cycle is also limited to rate_limit · cycle;
//   5. the supervisor compares |raw offset| and |rate of the smoothed offset| with per-joint
//      tolerances: when one is exceeded, or the input is NaN/Inf, or cycles were lost, the
//      compensation is deactivated and faded out over fade_out_s with a raised-cosine ramp (no
//      step), and the event is logged with its cause. Re-activation is explicit (reactivate()),
//      or automatic with PrecontrolOptions::auto_engage (below);
//   6. engagement (auto_engage): a stream may start, or resume after a fault, in the middle of a
//      motion, where the models' restart state (at rest at the current desired value) is wrong
//      and their first outputs are a transient, not the joint's error. The models then run for
//      engage_settle_s with the supervisor's tolerances not checked and the offset held at zero,
//      and the offset is then faded in with a raised-cosine ramp over fade_out_s (state
//      kEngaging); after a deactivation the precontrol re-engages itself once it has had
//      reengage_after_s of valid, consecutive input. A caller's own fault (fault()) restarts that
//      wait.
//
// Real-time rules inside cycle(): no heap allocation, no exception, no lock, bounded work; the
// state has a fixed size (kMax* below). Events go to a fixed ring buffer the caller reads
// between cycles. Cycle times: the table's model runs at its own sample time T; a caller cycle
// of m·T (m = 1..8, e.g. 4 ms for KUKA RSI / ABB EGM with a 2 ms table) runs the model m times
// per call on linearly interpolated desired values; a caller cycle of T/m (e.g. 1 ms) runs the
// model every m-th call and interpolates its output. Other ratios are refused at construction.
#include <array>
#include <cstdint>
#include <string>

#include "ident/arx_step_kernel.hpp"
#include "ident/parameter_table.hpp"

namespace imscal::ident {

inline constexpr int kPrecontrolJoints = 6;
inline constexpr int kMaxPrecontrolOrder = 64;     // na, nb
inline constexpr int kMaxPrecontrolDeadTime = 64;  // d [samples]
inline constexpr int kMaxPrecontrolCells = 16;     // cells per joint (<= 32: a bit mask)
inline constexpr int kPrecontrolEventCapacity = 256;

inline constexpr double kEnvelopeTolerance = 1.5;      // offset tolerance / envelope
inline constexpr double kEnvelopeRateTolerance = 3.0;  // rate tolerance / rate envelope
inline constexpr double kEnvelopeRateLimit = 4.0;      // output rate limit / rate envelope

struct PrecontrolOptions {
  double caller_cycle_s = 0.002;
  // Per joint; 0 selects the default: from the table's envelope of what the joint's models were
  // identified on (JointParameters::offset_envelope_rad and _rate_...), tolerance
  // kEnvelopeTolerance x envelope, rate limit kEnvelopeRateLimit x rate envelope (an offset or a
  // rate beyond them means the table is applied outside its data); for a table without the
  // envelope 5 mrad, 0.5 rad/s and 0.2 rad/s. (kEnvelopeRateTolerance for the rate tolerance.)
  std::array<double, kPrecontrolJoints> offset_tolerance_rad{};
  std::array<double, kPrecontrolJoints> rate_tolerance_rad_s{};
  std::array<double, kPrecontrolJoints> rate_limit_rad_s{};
  double smoothing_time_constant_s = 0.004;      // τ of the critically damped smoother
  double fade_out_s = 0.2;                       // deactivation ramp
  double backlash_velocity_scale_rad_s = 0.002;  // v_b of the tanh transition
  int max_lost_cycles = 0;  // lost cycles bridged by holding the last input (more: deactivate)
  // Engagement (see above); off: active from the first cycle, re-activation only explicit.
  bool auto_engage = false;
  double engage_settle_s = 0.2;   // models run, offset held at 0, tolerances not checked
  double reengage_after_s = 0.5;  // valid input needed after a deactivation before re-engaging
  // > 0: a desired angle moving faster than this between two cycles is a jump of the set-point
  // (deactivation, cause kInputJump) [rad/s]; 0: not checked.
  double max_input_speed_rad_s = 0.0;
};

enum class PrecontrolState : std::uint8_t { kActive, kFadingOut, kInactive, kEngaging };

enum class PrecontrolCause : std::uint8_t {
  kNone,
  kOffsetTolerance,  // |raw offset| > tolerance
  kRateTolerance,    // |offset rate| > tolerance
  kInvalidInput,     // NaN / Inf desired angle or payload
  kLostCycles,       // the cycle counter jumped by more than max_lost_cycles + 1
  kOutsideTable,     // operating point outside the identified grid (not a deactivation)
  kReactivated,
  kMissingTorque,  // the table's models need the model torque and the caller gave none
  kInputJump,      // a desired angle moved faster than max_input_speed_rad_s
  kCallerFault,    // the caller reported a fault (fault()); value: the caller's code
  kEngaging,       // (re-)engagement started (auto_engage)
  kEngaged,        // the offset is fully faded in
};
const char* to_string(PrecontrolCause cause);
// "active", "fading_out", "inactive", "engaging" (the offsets file's `state` column).
const char* to_string(PrecontrolState state);

struct PrecontrolEvent {
  std::uint64_t cycle = 0;
  std::int8_t joint = -1;  // -1: all joints
  PrecontrolCause cause = PrecontrolCause::kNone;
  double value = 0.0;  // the offending value (rad, rad/s, lost cycles, ...)
};

struct PrecontrolOutput {
  std::array<double, kPrecontrolJoints> offset_rad{};
  PrecontrolState state = PrecontrolState::kActive;
  bool outside_table = false;
};

class Precontrol {
 public:
  // Refuses (returns false with the reason in *why) a table for another robot, with another
  // joint count, sizes beyond the fixed capacity, non-finite parameters, or a caller cycle that
  // is not m·T or T/m. On success *out is ready (the only allocation-free object afterwards).
  static bool create(const ParameterTable& table, const std::string& robot,
                     const PrecontrolOptions& options, Precontrol* out, std::string* why);

  // One control cycle. cycle_counter: the caller's cycle number (consecutive normally).
  // q_desired_rad: the desired joint angles of the cycle, or, for a table with preview_cycles
  // P > 0 (inverse form), those P table cycles ahead; the offset is for the current cycle.
  PrecontrolOutput cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                         double payload_kg, std::uint64_t cycle_counter) noexcept;
  // The same with the joint torques of the robot's rigid-body model along the desired path at
  // the time of q_desired_rad [N m], for tables whose models take the model torque as a further
  // input (needs_model_torque()); without them such a table deactivates (kMissingTorque).
  PrecontrolOutput cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                         double payload_kg,
                         const std::array<double, kPrecontrolJoints>& model_torque_nm,
                         std::uint64_t cycle_counter) noexcept;
  bool needs_model_torque() const noexcept { return needs_torque_; }

  // Explicit re-activation after a deactivation: the models restart from the current desired
  // values (at rest: zero error) and the offsets rise smoothly from zero.
  void reactivate() noexcept;

  // A fault the caller detected (a malformed or late message, an unknown robot, ...): the
  // compensation is faded out as for the supervisor's own causes (kCallerFault, `code` logged as
  // the value) and an automatic re-engagement waits reengage_after_s from here.
  void fault(std::uint64_t cycle_counter, double code) noexcept;

  PrecontrolState state() const noexcept { return state_; }
  // The options in force, with the per-joint defaults resolved from the table.
  const PrecontrolOptions& options() const noexcept { return options_; }
  // Events since the last call (oldest first), copied out; the ring keeps the newest
  // kPrecontrolEventCapacity and counts what it dropped.
  int read_events(PrecontrolEvent* out, int capacity) noexcept;
  std::uint64_t dropped_events() const noexcept { return dropped_events_; }

 private:
  // Histories are rings stored twice (each value written at i and i + ring): the newest-first
  // window of any length up to the ring size is then contiguous, so the model's dot products
  // run over plain arrays (vectorised) without index wrapping.
  // The model's sums (ident/arx_step_kernel.hpp) each run over their own length (na, nb, nx_e)
  // padded to a multiple of kArxStepLanes with zero coefficients: no remainder loop (the reads
  // past na, nb, nx_e stay inside the rings and are multiplied by 0).
  static_assert(kMaxPrecontrolOrder <= kArxStepMaxTerms);
  static_assert(kMaxPrecontrolOrder % kArxStepLanes == 0);
  static constexpr int kInputRing = 128;  // power of two >= d + longest sum
  static_assert(kInputRing >= kMaxPrecontrolOrder + kMaxPrecontrolDeadTime);
  static constexpr int kOutputRing = kMaxPrecontrolOrder;  // q̂ history
  static_assert((kOutputRing & (kOutputRing - 1)) == 0);
  static constexpr int kSpeedRing = 128;  // > the largest backlash lag accepted [cycles]
  struct OutputHistory {
    std::array<double, 2 * kOutputRing> y{};  // q̂ history, newest at y[pos]
    int pos = 0;
  };
  struct JointModel {
    int cells = 0;
    // Per cell its model (contiguous: the kernel runs over all of them) and its own q̂ history.
    std::array<ArxCellCoefficients, kMaxPrecontrolCells> model{};
    std::array<OutputHistory, kMaxPrecontrolCells> output_history{};
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
    std::array<double, 2 * kInputRing> u{};  // q_d history, newest at u[u_pos]
    int u_pos = 0;
    // Further inputs' histories (table order), newest at x[e][u_pos].
    std::array<std::array<double, 2 * kInputRing>, kArxStepMaxExtras> x{};
    double last_error = 0.0;      // blended Δq̂ of the last model step
    double previous_error = 0.0;  // the one before (for output interpolation at T/m cycles)
    double smooth = 0.0, smooth_rate = 0.0;  // smoother state
    double output = 0.0;                     // last offset handed out
  };

  void model_step(JointModel& joint, double q_desired, double speed, double acceleration,
                  double payload, double torque, bool& outside) noexcept;
  // The further inputs' values of a model step at input x [rad] (ident/exogenous_inputs.hpp),
  // table order; advances the joint's gear-mode filter by one model step.
  std::array<double, kArxStepMaxExtras> extra_values(JointModel& joint, double x, double speed,
                                                     double torque) const noexcept;
  void restart_models(const std::array<double, kPrecontrolJoints>& q_desired,
                      const std::array<double, kPrecontrolJoints>& torque) noexcept;
  PrecontrolOutput run_cycle(const std::array<double, kPrecontrolJoints>& q_desired_rad,
                             double payload_kg,
                             const std::array<double, kPrecontrolJoints>* model_torque_nm,
                             std::uint64_t cycle_counter) noexcept;
  void deactivate(std::uint64_t cycle, int joint, PrecontrolCause cause, double value) noexcept;
  // The input checks of a cycle (validity, counter, jumps); false: the input is not used.
  bool accept_input(const std::array<double, kPrecontrolJoints>& q_desired_rad, double payload_kg,
                    const std::array<double, kPrecontrolJoints>* model_torque_nm,
                    std::uint64_t cycle_counter,
                    std::array<double, kPrecontrolJoints>& torque) noexcept;
  // Steps the engagement and re-engagement timers; the fade-in factor of the offset (0..1).
  double engagement_gain(bool valid, std::uint64_t cycle_counter) noexcept;
  void start_engaging(std::uint64_t cycle_counter) noexcept;
  void compose_output(double engagement_gain, PrecontrolOutput& out) noexcept;
  void log(std::uint64_t cycle, int joint, PrecontrolCause cause, double value) noexcept;

  PrecontrolOptions options_;
  double model_sample_s_ = 0.002;
  double smoother_decay_ = 0.0;  // exp(-caller cycle / τ), the smoother's decay per call
  int steps_per_call_ = 1;       // caller cycle = steps · T
  int calls_per_step_ = 1;       // caller cycle = T / calls
  int call_phase_ = 0;
  std::array<JointModel, kPrecontrolJoints> joints_{};
  std::array<double, kPrecontrolJoints> last_q_{};
  std::array<double, kPrecontrolJoints> last_torque_{};
  std::array<double, kPrecontrolJoints> last_speed_{};
  int extra_count_ = 0;                                 // further inputs of every cell's model
  std::array<TableInput, kArxStepMaxExtras> inputs_{};  // the first extra_count_: table order
  bool needs_torque_ = false;                           // one of them is the model torque
  double last_payload_ = 0.0;
  bool started_ = false;
  std::uint64_t last_cycle_ = 0;
  PrecontrolState state_ = PrecontrolState::kActive;
  double fade_elapsed_s_ = 0.0;
  double engage_elapsed_s_ = 0.0;  // since the (re-)engagement started
  double valid_for_s_ = 0.0;       // valid consecutive input while inactive
  std::array<double, kPrecontrolJoints> fade_from_{};
  bool was_outside_ = false;
  std::array<PrecontrolEvent, kPrecontrolEventCapacity> events_{};
  int event_head_ = 0, event_count_ = 0;
  std::uint64_t dropped_events_ = 0;
};

}  // namespace imscal::ident
