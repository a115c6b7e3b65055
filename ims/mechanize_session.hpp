#pragma once
// A mechanization session as `imscal mechanize` runs it: a raw IMS record read (rates converted
// to increments, the unit's error model applied on read), its initial attitude from the options
// or from a coarse alignment over its first seconds at rest (ims/coarse_alignment.hpp), then the
// strapdown mechanization (ims/strapdown.hpp) or, with a sensor spec, the zero-velocity-aided
// smoother with 1-sigma columns (ims/zupt_smoother.hpp): the trajectory of the sensor frame S in
// W (ENU), position and velocity starting at zero (its start: ims/mechanization_start.hpp). Bad
// options are InputErrors naming the command line's option.
#include <optional>
#include <string>
#include <vector>

#include "ims/nav_state.hpp"
#include "ims/nav_trajectory_io.hpp"

namespace imscal::ims {

struct MechanizeSessionOptions {
  std::string input;             // raw IMS file (.csv, .imsb, .imu PSINS)
  std::string initial_attitude;  // "ROLL,PITCH,HEADING" [deg]; or align_s
  std::optional<double> align_s;
  std::string site;           // "LAT,LON,H" [deg, deg, m]; empty: the file's
  std::string smooth_spec;    // sensor spec YAML: zero-velocity smoothing
  std::string sensor_errors;  // sensor error model YAML applied on read
  // Heading from an external reference, replacing the gyrocompassed one: a few seconds of
  // gyrocompassing give degrees (sigma ~ gyro noise / horizontal Earth rate).
  std::optional<double> heading_deg;
  double heading_sigma_deg = 0.001;
};

struct MechanizedTrajectory {
  std::vector<NavState> states;
  std::optional<std::vector<NavSigma>> sigmas;  // the smoother's 1-sigma (with smooth_spec)
  std::string summary;  // what was done, the initial attitude's source, the final state
};

MechanizedTrajectory mechanize_session(const MechanizeSessionOptions& options);

}  // namespace imscal::ims
