#pragma once
// The robot plant: rigid-body arm (sim/rigid_body_dynamics.hpp) driven through six drives
// (sim/drive_model.hpp) by six joint controllers (sim/joint_controller.hpp) that follow a
// desired joint path (sim/desired_path.hpp). Fixed-step classical RK4 at
// PlantConfig::integration_step_s (default 0.5 ms = a quarter of the 2 ms control cycle); the
// controllers run at the start of each cycle and their torque is held for the whole cycle (so
// every RK4 step sees a smooth right-hand side apart from the backlash contact).
//
// Per joint the state is link angle/rate (q, qd) and motor angle/rate (theta, thetad; motor
// angle / N). Rigid drives: theta is integrated and q = theta - te(theta) follows; massless
// motors: q is integrated and theta follows statically (drive_model.hpp). The equations:
//   link:  M(q) qdd + C(q, qd) qd + G(q) = tau_link
//   elastic: tau_link = tau_g - s f(qd);   J thetadd = tau - (1 - s) f(thetad) - (1 - te') tau_g
//            (s = the link share of the friction: JointEffects::link_friction_fraction, 1 with
//            friction_at_link)
//   rigid:   J thetadd + (1 - te') tau_link = tau - f(thetad),  q = theta - te(theta)
//   massless motor: tau_link = tau - f(qd)
// solved jointly as (M + diag(J_rigid / (1 - te')^2)) qdd = rhs with one 6x6 LDLT.
//
// Dead time: joint i's controller uses the desired sample round(dead_time_s / cycle) cycles old
// (the first sample before the start). Payload changes (DesiredJointSample::payload_index) take
// effect, physically and undelayed, at the cycle where the index changes (the planner changes it
// only at rest) and rebuild the KDL solvers.
//
// Start: at rest at the first desired sample (motor encoders = q_desired(0)), gravity statically
// balanced: link sag and spring preload solved for, controller integrators preloaded with the
// holding torque, so the plant starts without a transient.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <vector>

#include "sim/desired_path.hpp"
#include "sim/drive_model.hpp"
#include "sim/joint_controller.hpp"
#include "sim/plant_config.hpp"
#include "sim/rigid_body_dynamics.hpp"

namespace imscal::sim {

struct PlantSample {
  double t_s = 0.0;
  calib::JointVector q_link_rad = calib::JointVector::Zero();
  calib::JointVector qd_link_rad_s = calib::JointVector::Zero();
  calib::JointVector qdd_link_rad_s2 = calib::JointVector::Zero();
  calib::JointVector q_motor_rad = calib::JointVector::Zero();   // motor angle / N: the encoder
  calib::JointVector tau_drive_nm = calib::JointVector::Zero();  // held controller output
};

struct PlantLog {
  std::vector<PlantSample> samples;  // every output_interval_s from t = 0 to the path's end
};

// The integrated state; for rigid drives q, qd are derived from theta, for massless motors
// theta, thetad from q (see above); the other slots are kept consistent after every step.
struct PlantState {
  double t_s = 0.0;
  calib::JointVector q_rad = calib::JointVector::Zero();
  calib::JointVector qd_rad_s = calib::JointVector::Zero();
  calib::JointVector theta_rad = calib::JointVector::Zero();
  calib::JointVector thetad_rad_s = calib::JointVector::Zero();
};

class PlantSimulator {
 public:
  // Throws std::invalid_argument for an unusable config or path (step does not divide the
  // cycle, path cycle != controller cycle, empty path, payload index out of range).
  PlantSimulator(const PlantConfig& config, const DesiredJointPath& path);

  // Advances one control cycle (controller update, then RK4 steps); false once at the path end.
  bool run_cycle(const std::function<void(const PlantSample&)>& per_step_sample = {});
  bool finished() const { return cycle_index_ + 1 >= path_.samples.size(); }

  // The sample at the current time (evaluates the dynamics once for qdd).
  PlantSample current_sample();
  const PlantState& state() const { return state_; }
  // Replaces the state (tests: non-trivial initial conditions). Slots derived for the drive kind
  // are recomputed from the integrated ones.
  void set_state(const PlantState& state);
  const calib::JointVector& drive_torque_nm() const { return torque_; }

  // Kinetic energy of links and motors + gravity potential + spring energy [J].
  double mechanical_energy_j();

  const DriveModel& drive(int joint) const { return drives_[joint]; }
  RigidBodyDynamics& dynamics() { return dynamics_; }

 private:
  using StateVector = Eigen::Matrix<double, 4 * calib::kJointCount, 1>;
  StateVector pack(const PlantState& s) const;
  PlantState unpack(const StateVector& x, double t_s) const;
  // Fills the derived slots (rigid: q from theta; massless: theta from q and the torque).
  void complete(PlantState& s) const;
  // State derivative under the held torque; also returns the link accelerations.
  StateVector derivative(const PlantState& s, calib::JointVector* qdd_out);
  void rk4_step(calib::JointVector* qdd_at_start);
  void start_at_rest();
  void apply_payload(int index);

  PlantConfig config_;
  DesiredJointPath path_;
  std::array<DriveModel, calib::kJointCount> drives_;
  std::array<JointController, calib::kJointCount> controllers_;
  std::array<int, calib::kJointCount> delay_cycles_{};
  RigidBodyDynamics dynamics_;
  int steps_per_cycle_ = 4;
  int payload_index_ = 0;
  std::size_t cycle_index_ = 0;  // the cycle starting at the current time
  long step_index_ = 0;
  PlantState state_;
  calib::JointVector torque_ = calib::JointVector::Zero();
};

// Runs the whole path. output_interval_s must be a multiple of the integration step.
PlantLog simulate_plant(const PlantConfig& config, const DesiredJointPath& path,
                        double output_interval_s,
                        const std::function<void(double fraction_done)>& progress = {});

double mechanical_energy_j(PlantSimulator& simulator);

}  // namespace imscal::sim
