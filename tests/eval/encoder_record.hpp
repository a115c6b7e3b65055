#pragma once
// The record a robot log gives of a simulated run, without the IMS: desired path, the motor
// encoders (q_internal), the link angles as q_measured and the payload mass the program names
// (the log's, whatever the plant carries). The encoder-balance tests need no more.
#include <algorithm>
#include <string>

#include "ident/joint_error_io.hpp"
#include "sim/desired_path.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval::test {

inline ident::JointErrorLog encoder_record(const std::string& robot,
                                           const sim::DesiredJointPath& path,
                                           const sim::PlantLog& run) {
  ident::JointErrorLog log;
  log.robot = robot;
  log.cycle_s = path.cycle_s;
  log.joint_names = {"A1", "A2", "A3", "A4", "A5", "A6"};
  log.q_desired_rad.assign(6, {});
  log.q_measured_rad.assign(6, {});
  log.q_internal_rad.assign(6, {});
  for (std::size_t k = 0; k < std::min(path.samples.size(), run.samples.size()); ++k) {
    log.time_s.push_back(path.samples[k].t_s);
    log.payload_kg.push_back(
        path.payloads[std::size_t(path.samples[k].payload_index)].body.mass_kg);
    for (std::size_t j = 0; j < 6; ++j) {
      log.q_desired_rad[j].push_back(path.samples[k].q_rad(int(j)));
      log.q_measured_rad[j].push_back(run.samples[k].q_link_rad(int(j)));
      log.q_internal_rad[j].push_back(run.samples[k].q_motor_rad(int(j)));
    }
  }
  return log;
}

}  // namespace imscal::eval::test
