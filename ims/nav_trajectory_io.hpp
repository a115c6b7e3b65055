#pragma once
// Navigation trajectories (a NavState series in W, ims/nav_state.hpp) as files.
//
// CSV, one header line with units, then one line per state:
//   t_s,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s
// optionally followed by the 1-sigma columns (when sigmas are given)
//   sigma_att_e_rad,sigma_att_n_rad,sigma_att_u_rad,sigma_vx_m_s,sigma_vy_m_s,sigma_vz_m_s,
//   sigma_x_m,sigma_y_m,sigma_z_m
// (attitude error angles about the East, North and Up axes of W as in ims/error_state_model.hpp,
// then velocity and position). Position in m, attitude q_W_S (p_W = q_W_S * p_S), velocity
// relative to the Earth in m/s. Numbers are written in the shortest form that reads back to the
// same double.
//
// TUM (the format of common trajectory evaluation tools): a '#' comment header, then
//   t x y z qx qy qz qw
// separated by single spaces; same units and frames as the CSV.
//
// Both writers are atomic (core/atomic_file.hpp).
#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "core/atomic_file.hpp"
#include "ims/nav_state.hpp"

namespace imscal::ims {

// 1-sigma of (attitude error E, N, U [rad], velocity [m/s], position [m]) per state.
using NavSigma = Eigen::Matrix<double, 9, 1>;

struct NavTrajectory {
  std::vector<NavState> states;
  std::vector<NavSigma> sigmas;  // empty, or one per state
};

// sigmas: nullptr, or one per state (std::invalid_argument otherwise).
void write_trajectory_csv(const std::filesystem::path& file, const std::vector<NavState>& states,
                          const std::vector<NavSigma>* sigmas = nullptr,
                          Overwrite overwrite = Overwrite::kAllow);

void write_trajectory_tum(const std::filesystem::path& file, const std::vector<NavState>& states,
                          Overwrite overwrite = Overwrite::kAllow);

// Reads a CSV written by write_trajectory_csv. Lines starting with '#' before the header are
// skipped. Throws InputError (file, line, column) for a wrong header, a missing or extra field, a
// value that is not a finite number, a time that does not increase, a quaternion whose norm is
// not 1 within 1e-6, or a negative sigma. Quaternions are normalised on reading.
NavTrajectory read_trajectory_csv(const std::filesystem::path& file);

}  // namespace imscal::ims
