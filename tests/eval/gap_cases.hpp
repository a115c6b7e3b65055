#pragma once
// Cases of the withheld-effect harness (tests/eval/test_gap_harness.cpp, test_diagnose_cli.cpp):
// the simulator runs tests/data/scenarios/gap-program.yaml with a base set of effects ("sim") and
// with one or two effects added or injected ("real", plus measurement noise). The base is the
// robot's default plant with backlash off on every joint (so that backlash can be withheld on
// its own; an elastic gear without its play is then a clean second effect).
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "core/units.hpp"
#include "eval/gap_candidates.hpp"
#include "eval/gap_diagnosis.hpp"
#include "eval/gap_measurement_prior.hpp"
#include "eval/gap_nominal_plant.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"
#include "robot/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval::test {

struct WithheldEffect {
  std::string name;  // backlash, coulomb, elastic, transmission, time_offset, clock_offset (every
                     // joint's measurement delayed alike; `joint` unused), zero_offset,
                     // drift, resonance, operating_point; payload (`joint` unused: the mass loads
                     // every joint); errors of the IMS chain: kinematic (DH error of link
                     // `joint`), mounting, ims_scale, ims_bias (`joint` unused: they spread over
                     // the joints; Case::spread_joint says where they show most)
  int joint = 0;
  // > 0: the effect resized rather than switched: "real" runs the joint's parameter times this
  // factor, "sim" the robot file's value (coulomb: the Coulomb friction torque); transmission: the
  // error's harmonic per motor revolution (another order than the first).
  double scale = 0.0;
  // > 0: the effect's size, not drawn from the seed: transmission error amplitude [arcsec],
  // payload mass added [kg].
  double size = 0.0;
};

// The measurement noise added to a case's "real" q_measured. kLow: the harness's (white 3e-6 rad
// plus a first-order 50 ms coloured part of 3e-6 rad, ~3 um at 1 m). kImsChain: the IMS chain's
// own error on joint angles, measured 3e-5..9e-5 rad RMS per joint through `simulate` ->
// `calibrate --frames` -> `model-joint-errors` on a control (test_gap_harness_wide.cpp): per joint
// an RMS drawn in 5e-5..8e-5 rad, 90 % of its variance a first-order part of 1 s (the chain's
// error holds at rest and moves with the motions: frames, heading and biases seen from another
// pose) and 10 % white; the drawn RMS is the case's noise floor (the header key
// q_measured_sigma_rms_rad, as calibrate writes the smoother's sigma), which the measurement
// budget tests the gap against.
enum class NoiseLevel { kLow, kImsChain };

inline EffectKind expected_kind(const std::string& name) {
  if (name == "backlash") return EffectKind::kBacklash;
  if (name == "coulomb") return EffectKind::kCoulombFriction;
  if (name == "elastic") return EffectKind::kGearCompliance;
  if (name == "transmission") return EffectKind::kTransmissionError;
  if (name == "time_offset") return EffectKind::kTimeOffset;
  if (name == "clock_offset") return EffectKind::kClockOffset;
  if (name == "zero_offset") return EffectKind::kZeroOffset;
  if (name == "payload") return EffectKind::kPayloadMismatch;
  if (name == "kinematic") return EffectKind::kKinematicParameters;
  if (name == "mounting") return EffectKind::kSensorMounting;
  if (name == "ims_scale") return EffectKind::kImsScaleFactor;
  if (name == "ims_bias") return EffectKind::kImsBias;
  if (name == "resonance") return EffectKind::kResonance;
  if (name == "operating_point") return EffectKind::kOperatingPoint;
  return EffectKind::kThermalDrift;
}

inline bool is_chain_effect(const std::string& name) {
  return name == "kinematic" || name == "mounting" || name == "ims_scale" || name == "ims_bias";
}

// Effects that act on several joints at once (no source joint): located where they show most.
inline bool spreads_over_joints(const std::string& name) {
  return is_chain_effect(name) || name == "payload" || name == "clock_offset";
}

// The joint angles the nominal model's inverse kinematics returns for the flange pose `target`,
// by Newton steps from `q` (the link-side angles, within ~1e-3 rad of the solution: three steps
// reach ~1e-12 rad).
inline calib::JointVector solve_near(const calib::KinematicModel& kin,
                                     const Eigen::Isometry3d& target, calib::JointVector q) {
  for (int it = 0; it < 3; ++it) {
    const Eigen::Isometry3d T = calib::forward_kinematics<double>(kin, q);
    const Eigen::Isometry3d e = T.inverse() * target;  // body error of the flange
    const Eigen::AngleAxisd rotation(e.linear());
    Eigen::Matrix<double, 6, 1> twist;
    twist << e.translation(), rotation.angle() * rotation.axis();
    const calib::Jacobian jg = calib::geometric_jacobian(kin, q);
    Eigen::Matrix<double, 6, 6> jb;
    jb.topRows<3>() = T.linear().transpose() * jg.topRows<3>();
    jb.bottomRows<3>() = T.linear().transpose() * jg.bottomRows<3>();
    q += jb.partialPivLu().solve(twist);
  }
  return q;
}

inline Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  return angle > 0.0 ? Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
}

struct GapWorld {
  GapWorld() = default;
  // Another motion program (a motion program file, datasets/FORMAT.md).
  explicit GapWorld(std::string program) : program_file(std::move(program)) {}

  calib::RobotDescription robot =
      calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  std::string program_file = IMSCAL_TEST_DATA_DIR "/scenarios/gap-program.yaml";
  sim::DesiredJointPath path = sim::plan_motion(robot, sim::load_motion_program(program_file));
  sim::PlantConfig base = [this] {
    sim::PlantConfig c = sim::make_plant_config(robot, nullptr);
    for (auto& e : c.effects) e.backlash = false;
    return c;
  }();
  sim::PlantLog base_log = sim::simulate_plant(base, path, path.cycle_s);

  // Joint errors of a plant log (q_measured = link side, q_internal = motor / N).
  ident::JointErrorLog log_of(const sim::PlantLog& plant) const {
    ident::JointErrorLog log;
    log.robot = robot.name;
    log.cycle_s = path.cycle_s;
    for (const auto& j : robot.joints) log.joint_names.push_back(j.name);
    const std::size_t n = path.samples.size();
    log.q_desired_rad.assign(6, std::vector<double>(n));
    log.q_measured_rad = log.q_desired_rad;
    log.q_internal_rad = log.q_desired_rad;
    for (std::size_t k = 0; k < n; ++k) {
      log.time_s.push_back(path.samples[k].t_s);
      log.payload_kg.push_back(
          path.payloads[std::size_t(path.samples[k].payload_index)].body.mass_kg);
      for (int j = 0; j < 6; ++j) {
        log.q_desired_rad[std::size_t(j)][k] = path.samples[k].q_rad[j];
        log.q_measured_rad[std::size_t(j)][k] = plant.samples[k].q_link_rad[j];
        log.q_internal_rad[std::size_t(j)][k] = plant.samples[k].q_motor_rad[j];
      }
    }
    return log;
  }

  // A case: "real" = the plant with the effects on (plus injected ones and IMS-chain-like noise
  // on q_measured: white 3e-6 rad plus a first-order 50 ms coloured part of 3e-6 rad, ~3 um at
  // 1 m), "sim" = the plant with them off. Backlash and the transmission error are off in the
  // base (real: switched on); Coulomb friction and the elastic gear are on in the base (sim:
  // switched off). Effect sizes vary with the seed (x0.7..1.3).
  struct Case {
    ident::JointErrorLog real;             // with noise
    ident::JointErrorLog real_noise_free;  // = "the sim re-run with the true effects on"
    std::vector<std::vector<double>> sim_joint_error_rad;
    // The joint where the noise-free gap has the most energy (where an effect that spreads over
    // the joints shows most).
    int spread_joint = -1;
    // The identified error model's operating-point grid ("operating_point" cases): per joint one
    // speed dimension; cells beyond the identified speed are filled, not identified.
    std::optional<ident::ParameterTable> table;
    // The nominal model whose simulation is "sim" (eval/gap_nominal_plant.hpp).
    NominalPlant nominal;
  };

  // Errors of the IMS chain injected into q_measured: the flange pose the chain would measure
  // from the true (link-side) motion with the error, through the nominal inverse kinematics.
  // Returns the joint where the injected error has the most energy.
  int inject_chain_error(const WithheldEffect& e, std::mt19937_64& rng,
                         ident::JointErrorLog& log) const {
    std::uniform_real_distribution<double> size(0.7, 1.3);
    std::normal_distribution<double> unit(0.0, 1.0);
    const auto random_direction = [&] {
      return Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    };
    const calib::KinematicModel& kin = robot.kinematics;
    const std::size_t n = log.sample_count();
    const auto link_joints = [&](std::size_t k) {
      calib::JointVector q;
      for (int j = 0; j < 6; ++j) q[j] = log.q_measured_rad[std::size_t(j)][k];
      return q;
    };
    calib::KinematicModel real_kin = kin;
    // Sizes: DH lengths 0.1 mm, twists 0.2 mrad; mounting 0.5 mrad and 0.2 mm; gyro scale
    // 1000 ppm per axis; gyro bias 20 urad/s (4 deg/h): all x0.7..1.3, joint gaps ~1e-4 rad.
    const int parameter = int(rng() % 3);
    if (e.name == "kinematic") {
      auto& dh = real_kin.dh[std::size_t(e.joint)];
      if (parameter == 0) dh.a_m += 1e-4 * size(rng);
      if (parameter == 1) dh.alpha_rad += 2e-4 * size(rng);
      if (parameter == 2) dh.d_m += 1e-4 * size(rng);
    }
    const Eigen::Vector3d mount_rotation = 5e-4 * size(rng) * random_direction();
    const Eigen::Vector3d mount_translation = 2e-4 * size(rng) * random_direction();
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = rotation_exp(mount_rotation);
    D.translation() = mount_translation;
    Eigen::Vector3d gyro_scale;
    for (int i = 0; i < 3; ++i) gyro_scale[i] = 1e-3 * size(rng) * (unit(rng) > 0.0 ? 1 : -1);
    const Eigen::Vector3d gyro_bias = 2e-5 * size(rng) * random_direction();

    const Eigen::Isometry3d T0 = calib::forward_kinematics<double>(kin, link_joints(0));
    Eigen::Isometry3d previous = T0;
    Eigen::Matrix3d attitude = T0.linear();  // the chain's integrated attitude
    std::vector<calib::JointVector> measured(n);
    for (std::size_t k = 0; k < n; ++k) {
      const calib::JointVector q = link_joints(k);
      const Eigen::Isometry3d T = calib::forward_kinematics<double>(kin, q);
      Eigen::Isometry3d target = T;
      if (e.name == "kinematic") target = calib::forward_kinematics<double>(real_kin, q);
      if (e.name == "mounting") target = T0 * D * T0.inverse() * T * D.inverse();
      if (e.name == "ims_scale" || e.name == "ims_bias") {
        if (k > 0) {
          const Eigen::AngleAxisd step(previous.linear().transpose() * T.linear());
          Eigen::Vector3d phi = step.angle() * step.axis();
          if (e.name == "ims_scale") phi += gyro_scale.cwiseProduct(phi);
          if (e.name == "ims_bias") phi += gyro_bias * (log.time_s[k] - log.time_s[k - 1]);
          attitude = attitude * rotation_exp(phi);
        }
        target.linear() = attitude;
      }
      previous = T;
      measured[k] = solve_near(kin, target, q);
    }
    std::vector<double> energy(6, 0.0);
    for (std::size_t k = 0; k < n; ++k)
      for (int j = 0; j < 6; ++j) {
        double& qm = log.q_measured_rad[std::size_t(j)][k];
        energy[std::size_t(j)] += (measured[k][j] - qm) * (measured[k][j] - qm);
        qm = measured[k][j];
      }
    return int(std::max_element(energy.begin(), energy.end()) - energy.begin());
  }
  // NoiseLevel::kImsChain: each joint's noise scaled to its drawn RMS over the record. The drawn
  // RMS is written into the log's header as the noise floor (kNoiseFloorKey), as `imscal
  // calibrate` writes the smoother's sigma into a measured joint_errors.csv: the diagnosis's
  // measurement budget then tests the case as it tests a real record.
  static void add_ims_chain_noise(std::mt19937_64& rng, ident::JointErrorLog& log) {
    std::uniform_real_distribution<double> rms_rad(5e-5, 8e-5);
    std::vector<double> floor_rad;
    std::normal_distribution<double> unit(0.0, 1.0);
    const double phi = std::exp(-log.cycle_s / 1.0);
    for (auto& qm : log.q_measured_rad) {
      const double rms = rms_rad(rng);
      floor_rad.push_back(rms);
      std::vector<double> slow(qm.size()), fast(qm.size());
      double ar = unit(rng), e_slow = 0.0, e_fast = 0.0;
      for (std::size_t k = 0; k < qm.size(); ++k) {
        ar = phi * ar + std::sqrt(1.0 - phi * phi) * unit(rng);
        slow[k] = ar, fast[k] = unit(rng);
        e_slow += ar * ar, e_fast += fast[k] * fast[k];
      }
      const double n = double(qm.size());
      const double a = rms * std::sqrt(0.9 * n / e_slow), b = rms * std::sqrt(0.1 * n / e_fast);
      for (std::size_t k = 0; k < qm.size(); ++k) qm[k] += a * slow[k] + b * fast[k];
    }
    log.metadata.emplace_back(kNoiseFloorKey, noise_floor_header_value(floor_rad));
  }

  // One speed dimension per joint: joint `joint` identified up to v_id (the band above filled),
  // the others identified over their whole range.
  ident::ParameterTable operating_point_table(int joint, double v_id) const {
    ident::ParameterTable t;
    t.robot = robot.name;
    t.sample_time_s = path.cycle_s;
    for (int j = 0; j < 6; ++j) {
      ident::JointParameters jp;
      jp.name = robot.joints[std::size_t(j)].name;
      const double top = robot.joints[std::size_t(j)].max_velocity_rad_s;
      ident::CellParameters identified;
      identified.bands = {0};
      if (j == joint) {
        jp.dimensions.push_back({ident::OperatingQuantity::kSpeed, {0.0, v_id, top}});
        ident::CellParameters filled;
        filled.bands = {1};
        filled.status = ident::CellStatus::kFilled;
        filled.filled_from = 0;
        filled.reason = "no identification data at these speeds";
        jp.cells = {identified, filled};
      } else {
        jp.dimensions.push_back({ident::OperatingQuantity::kSpeed, {0.0, top}});
        jp.cells = {identified};
      }
      t.joints.push_back(jp);
    }
    return t;
  }

  Case make_case(const std::vector<WithheldEffect>& effects, std::uint64_t seed,
                 NoiseLevel noise = NoiseLevel::kLow) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> size(0.7, 1.3);
    sim::PlantConfig real_config = base, sim_config = base;
    sim::DesiredJointPath real_path = path;
    bool real_changed = false, sim_changed = false;
    for (const auto& e : effects) {
      auto& re = real_config.effects[std::size_t(e.joint)];
      auto& se = sim_config.effects[std::size_t(e.joint)];
      if (e.name == "backlash") re.backlash = real_changed = true;
      if (e.name == "transmission") {
        re.transmission_error = real_changed = true;
        re.transmission_error_shape.amplitude_rad *= 2.0 * size(rng);  // 28..52 arcsec
        if (e.size > 0.0) re.transmission_error_shape.amplitude_rad = e.size * kRadPerArcsec;
        if (e.scale > 0.0) re.transmission_error_shape.harmonic_per_motor_rev = e.scale;
      }
      if (e.name == "coulomb" && e.scale > 0.0) {
        real_config.robot.joints[std::size_t(e.joint)].drive.coulomb_nm *= e.scale;
        real_changed = true;
      } else if (e.name == "coulomb") {
        se.coulomb_friction = false, sim_changed = true;
      }
      if (e.name == "elastic") se.elastic_gear = se.gear_damping = false, sim_changed = true;
      if (e.name == "payload") {
        const double added_kg = 4.0 * size(rng);
        for (auto& p : real_path.payloads) p.body.mass_kg += e.size > 0.0 ? e.size : added_kg;
        real_changed = true;
      }
    }
    Case c;
    c.nominal = {sim_config, path, {}};
    const sim::PlantLog real_plant =
        real_changed ? sim::simulate_plant(real_config, real_path, path.cycle_s) : base_log;
    const sim::PlantLog sim_plant =
        sim_changed ? sim::simulate_plant(sim_config, path, path.cycle_s) : base_log;
    c.sim_joint_error_rad.assign(6, std::vector<double>(path.samples.size()));
    for (std::size_t k = 0; k < path.samples.size(); ++k)
      for (int j = 0; j < 6; ++j)
        c.sim_joint_error_rad[std::size_t(j)][k] =
            path.samples[k].q_rad[j] - sim_plant.samples[k].q_link_rad[j];
    ident::JointErrorLog log = log_of(real_plant);
    const std::size_t n = log.sample_count();
    for (const auto& e : effects)
      if (is_chain_effect(e.name)) inject_chain_error(e, rng, log);
    // The measurement stream lags by dt: q_m(t) = q_link(t - dt), linear interpolation.
    const auto delay = [&](std::vector<double>& qm, double dt) {
      const std::vector<double> q = qm;
      for (std::size_t k = 0; k < n; ++k) {
        const double x = std::clamp((log.time_s[k] - dt) / log.cycle_s, 0.0, double(n - 1));
        const std::size_t i = std::min(std::size_t(x), n - 2);
        qm[k] = q[i] + (x - double(i)) * (q[i + 1] - q[i]);
      }
    };
    for (const auto& e : effects) {
      auto& qm = log.q_measured_rad[std::size_t(e.joint)];
      if (e.name == "time_offset") delay(qm, 0.004 * size(rng));
      if (e.name == "clock_offset") {  // the measuring clock's offset: every joint at once
        // 0.5 ms: a gap of ~100 arcsec on the main axes, of the order of the other effects.
        const double dt = 0.0005 * size(rng);
        for (auto& q : log.q_measured_rad) delay(q, dt);
      }
      if (e.name == "zero_offset") {
        const double offset = 1.5e-4 * size(rng);
        for (double& v : qm) v -= offset;
      }
      if (e.name == "resonance") {
        // A lightly damped structural mode of the arm behind joint `joint`, excited by the
        // joint's commanded acceleration: x'' + 2 zeta w x' + w^2 x = -g qdd_d, seen by the
        // measurement as an angle. 7.3 Hz and zeta 0.04 lie between the candidate library's
        // grid points (eval/gap_candidates.cpp); integrated with RK4 in 8 substeps per cycle,
        // input held over the cycle. g: ~0.1 mrad of deflection at the program's accelerations.
        const double w = 2.0 * M_PI * 7.3 * size(rng), zeta = 0.04, g = 0.07 * size(rng);
        const double h = log.cycle_s / 8.0;
        double x = 0.0, v = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
          const double u =
              -g * path.samples[std::min(k, path.samples.size() - 1)].qdd_rad_s2[e.joint];
          const auto f = [&](double p, double q) {
            return std::pair{q, u - 2.0 * zeta * w * q - w * w * p};
          };
          for (int i = 0; i < 8; ++i) {
            const auto [k1x, k1v] = f(x, v);
            const auto [k2x, k2v] = f(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
            const auto [k3x, k3v] = f(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
            const auto [k4x, k4v] = f(x + h * k3x, v + h * k3v);
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
          }
          qm[k] += x;
        }
      }
      if (e.name == "operating_point") {
        // The error model was identified at speeds up to v_id = 45..65 % of the joint's top
        // speed in this program (the table's cells above are filled from below); beyond v_id the
        // real joint error departs from what the model extrapolates: a speed-dependent error
        // c sign(v) ((|v| - v_id) / v_id)^p (p 1..2, a drag or stiffening the slower runs never
        // excited; v the link's own velocity), c ~0.2 mrad at the top speed.
        double v_peak = 0.0;
        for (const auto& sample : path.samples)
          v_peak = std::max(v_peak, std::abs(sample.qd_rad_s[e.joint]));
        const double v_id =
            (0.45 + 0.2 * std::uniform_real_distribution<double>(0, 1)(rng)) * v_peak;
        const double p = 1.0 + std::uniform_real_distribution<double>(0, 1)(rng);
        const double c_size = 2e-4 * size(rng) / std::pow((v_peak - v_id) / v_id, p);
        const std::vector<double> q = qm;
        for (std::size_t k = 0; k < n; ++k) {
          const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, n - 1);
          const double v = (q[b] - q[a]) / (log.time_s[b] - log.time_s[a]);
          const double excess = std::max(0.0, std::abs(v) - v_id) / v_id;
          qm[k] -= c_size * (v > 0.0 ? 1.0 : -1.0) * std::pow(excess, p);
        }
        c.table = operating_point_table(e.joint, v_id);
      }
      if (e.name == "drift") {
        const double a = 2e-4 * size(rng), duration = log.time_s.back();
        for (std::size_t k = 0; k < n; ++k) {
          const double x = log.time_s[k] / duration;
          qm[k] -= a * (x + 0.5 * x * x);
        }
      }
    }
    c.real_noise_free = log;
    std::vector<double> energy(6, 0.0);
    for (std::size_t j = 0; j < 6; ++j)
      for (std::size_t k = 0; k < n; ++k) {
        const double g =
            log.q_desired_rad[j][k] - log.q_measured_rad[j][k] - c.sim_joint_error_rad[j][k];
        energy[j] += g * g;
      }
    c.spread_joint = int(std::max_element(energy.begin(), energy.end()) - energy.begin());
    if (noise == NoiseLevel::kImsChain) {
      add_ims_chain_noise(rng, log);
    } else {
      std::normal_distribution<double> white(0.0, 3e-6);
      const double phi = std::exp(-log.cycle_s / 0.05);
      for (auto& qm : log.q_measured_rad) {
        double ar = 0.0;
        for (double& v : qm) {
          ar = phi * ar + std::sqrt(1.0 - phi * phi) * white(rng);
          v += white(rng) + ar;
        }
      }
    }
    c.real = std::move(log);
    return c;
  }
};

// The held-out shrinkage the true effects give (the sim re-run with them on leaves only the noise
// of the real data) [%]: the truth a predicted shrinkage is scored against.
inline double true_heldout_shrinkage_percent(const GapWorld::Case& c, const GapSignals& signals) {
  const std::vector<bool> training = training_rows(signals, DiagnosisOptions{}.block_s);
  double e_gap = 0.0, e_noise = 0.0;
  for (std::size_t j = 0; j < signals.joint_count(); ++j)
    for (std::size_t k = 0; k < signals.sample_count(); ++k) {
      if (training[k]) continue;
      const double noise = c.real.q_measured_rad[j][k] - c.real_noise_free.q_measured_rad[j][k];
      e_gap += signals.gap_rad[j][k] * signals.gap_rad[j][k];
      e_noise += noise * noise;
    }
  return 100.0 * (1.0 - std::sqrt(e_noise / e_gap));
}

}  // namespace imscal::eval::test
