#pragma once
// Where a strapdown mechanization of a raw IMS file starts: the record read (rates turned into
// increments, the unit's error model applied), the Earth model at the site and the initial
// state, either from given angles or from a coarse alignment over the first seconds of the
// record at rest (with the heading optionally from an external reference). `imscal mechanize`
// and the Python module's `mechanize` start here. Position and velocity start at zero.
#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/nav_state.hpp"

namespace imscal::ims {

struct MechanizationRequest {
  std::filesystem::path input;  // raw IMS file (ims/imu_file.hpp)
  // Exactly one of the two: roll, pitch, heading [deg] (heading clockwise from North,
  // ims/coarse_alignment.hpp), or a coarse alignment over the first align_s seconds [s].
  std::optional<Eigen::Vector3d> initial_attitude_deg;
  std::optional<double> align_s;
  std::optional<Site> site;             // overrides the file's site
  std::filesystem::path sensor_errors;  // sensor error model YAML applied on read; empty: none
  // Heading from an external reference replacing the gyrocompassed one (with align_s) [deg].
  std::optional<double> heading_deg;
  double heading_sigma_deg = 0.001;
  // Where the options come from (the InputError's file), and their names there.
  std::string origin = "<command line>";
};

struct MechanizationStart {
  ImuSeries increments;  // from the first sample after initial.t_s
  std::unique_ptr<EarthModel> earth;
  NavState initial;
  std::string attitude_source;                                   // for the user
  Eigen::Vector3d attitude_sigma_rad = Eigen::Vector3d::Zero();  // E, N, U; from the alignment
};

// Throws InputError (the file's, or request.origin with the option's name) for what cannot start
// a mechanization: no site, fewer than two samples, an alignment interval outside the record.
MechanizationStart prepare_mechanization(const MechanizationRequest& request);

}  // namespace imscal::ims
