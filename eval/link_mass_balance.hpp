#pragma once
// The links' masses from the motor encoders' torque balance (ident/friction_levels.hpp), with
// 1σ, beside the nominal robot's: the balance of every joint A1–A5 gets one more column per
// link, the nominal model torque's change for +1 kg on that link (centre of mass and inertia
// kept) along the desired path; the mass changes are shared by all joints, each joint keeps its
// own drive columns (controller gains, constant, friction, motor inertia), which are projected
// out (separable least squares), each joint weighted by its residual variance times its
// correlation factor. The torque scale comes only from the model torque itself: the drive's
// gains are free, so a link's mass is seen only where its torque is not proportional to the
// rest of the model torque (the payload the log names, the other links, inertia against
// gravity). `unexplained_share` measures that per joint and link.
// Nothing reads the plant.
//
// Measured (decision 0063): it finds the masses only when the payload is known to about 1 % and
// its centre of mass to about 1 cm, which the lab's log does not give; `identify` does not call it.
//
// References (docs/references.md): [Ljung1999] (least squares), [Kunsch1989] (the
// delete-a-block jackknife of dependent rows), [Hollerbach2008] (dynamic
// identification: the rigid-body torque is linear in the links' inertial parameters).
#include <limits>
#include <string>
#include <vector>

#include "eval/model_torque.hpp"
#include "ident/friction_levels.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct LinkMassBalanceOptions {
  ident::FrictionLevelOptions balance;
  std::vector<int> links = {1, 2, 3, 4};  // 0-based links estimated (links 2–5)
  std::vector<int> joints = {0, 1, 2, 3, 4};
  double step_kg = 1.0;      // the columns' finite difference (the torque is linear in the mass)
  int jackknife_blocks = 8;  // record split into this many time blocks for the spread
  // > 0: only rows where every joint's desired speed is below this (rests and slow moves: the
  // gravity torque without the gear's dynamics) [rad/s].
  double quasi_static_speed_rad_s = 0.0;
  // > 0: the payload's mass is the logged one times 1 + f, f estimated with a Gaussian prior of
  // this σ (the lab's payload within ±10 %: 0.058); 0: the logged mass exactly.
  double payload_mass_prior_sigma = 0.0;
};

// A link's mass change, or (link −1) a payload parameter named in LinkMassBalance.
struct LinkMassEstimate {
  int link = 0;  // 0-based
  double nominal_kg = 0.0;
  double change_kg = std::numeric_limits<double>::quiet_NaN();           // estimate − nominal
  double sigma_kg = std::numeric_limits<double>::quiet_NaN();            // least squares' 1σ
  double jackknife_sigma_kg = std::numeric_limits<double>::quiet_NaN();  // over time blocks
};

struct LinkMassBalance {
  std::vector<LinkMassEstimate> links;  // the links, then the payload's parameters
  std::vector<std::string> payload_names;
  int dead_time_cycles = 0;
  // [joint][link]: the share of the link's column (its norm about its mean) that the joint's
  // drive columns leave unexplained: what the balance can see of the link (0: nothing).
  std::vector<std::vector<double>> unexplained_share;
  double condition_number = 0.0;  // of the weighted normal matrix, columns scaled to unit norm
};

// Throws std::invalid_argument when the log has no motor encoders or is not the model's.
LinkMassBalance identify_link_masses(const ident::JointErrorLog& log,
                                     const ModelTorqueSource& nominal,
                                     const LinkMassBalanceOptions& options = {});

}  // namespace imscal::eval
