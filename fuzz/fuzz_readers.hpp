#pragma once
// What each fuzz target feeds its input to, shared by the fuzz targets (fuzz/fuzz_*.cpp) and the
// regression test that replays the inputs fuzzing once found (tests/core/test_fuzz_regressions).
// A reader may accept the input or refuse it with an InputError; anything else is a bug.
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>

#include "calib/calibration_config.hpp"
#include "calib/frames_json.hpp"
#include "calib/master_slave_record.hpp"
#include "calib/mounting_report_json.hpp"
#include "calib/tool_imu_record.hpp"
#include "calib/tracker_poses.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/numeric_table.hpp"
#include "core/run_record.hpp"
#include "ident/identification_config.hpp"
#include "ident/identification_report.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "ims/imu_binary.hpp"
#include "ims/imu_csv.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "ims/psins_reader.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "online/egm_codec.hpp"
#include "online/rsi_datagram.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"
#include "sim/motion_program.hpp"
#include "sim/scenario.hpp"
#include "tools/run_config.hpp"

namespace imscal::fuzz {

// Every config parser on one YAML text; each may refuse it on its own.
inline void parse_yaml_configs(const std::string& text) {
  const ConfigNode root = ConfigNode::load_string(text, "fuzz.yaml");
  try {
    calib::parse_robot_description(root);
  } catch (const InputError&) {
  }
  try {
    ims::parse_sensor_spec(root);
  } catch (const InputError&) {
  }
  try {
    calib::parse_calibration_config(root);
  } catch (const InputError&) {
  }
  try {
    ident::load_identification_config(root);
  } catch (const InputError&) {
  }
  try {
    sim::parse_motion_program(root);
  } catch (const InputError&) {
  }
  ims::parse_sensor_error_model(root);
}

// The RSI datagram parser on raw bytes (it takes no file and throws nothing); an accepted
// datagram's set-points are written back as an answer, as the server does.
inline void parse_rsi_datagram(std::string_view bytes) {
  online::RsiRobotDatagram datagram;
  if (online::parse_rsi_robot_datagram(bytes, &datagram) != online::RsiParseError::kNone) return;
  std::array<char, 1024> answer{};
  online::write_rsi_answer(datagram.type_name(), datagram.setpoint_deg, datagram.ipoc,
                           answer.data(), int(answer.size()));
}

// The EGM codec on raw bytes (it takes no file and throws nothing): a datagram read as the
// controller's EgmRobot and, accepted, its measured joints written back as the answer, as the
// server writes its targets; the same codec for every input, as the server keeps it.
inline void parse_egm_datagram(std::string_view bytes) {
  static online::EgmCodec codec;
  online::EgmRobotDatagram datagram;
  if (codec.parse_robot(bytes, &datagram) != online::EgmParseError::kNone) return;
  std::array<double, online::kEgmAxes> joints_deg{};
  for (int a = 0; a < online::kEgmAxes && a < datagram.feedback_joints; ++a)
    joints_deg[std::size_t(a)] = datagram.feedback_deg[std::size_t(a)];
  std::array<char, 1024> answer{};
  codec.write_sensor(datagram.seqno, datagram.tm_ms, joints_deg, answer.data(), int(answer.size()));
}

// Reads `file` with the reader of `target` (the fuzz target's name without "fuzz_"); returns
// quietly when the reader accepts or refuses the input with an InputError.
inline void read_with(std::string_view target, const std::filesystem::path& file) {
  try {
    if (target == "imu_csv") {
      ims::read_imu_csv(file);
    } else if (target == "imu_binary") {
      ims::read_imu_binary(file);
    } else if (target == "psins") {
      ims::read_psins(file);
    } else if (target == "robot_log") {
      calib::read_robot_log_csv(file);
    } else if (target == "run_config") {
      tools::load_run_config(file);
    } else if (target == "numeric_table") {
      read_numeric_table(file);
    } else if (target == "tool_imu_record") {
      calib::read_tool_imu_record(file);
    } else if (target == "tracker_poses") {
      calib::read_tracker_poses(file);
    } else if (target == "increment_imu") {
      calib::read_increment_imu_csv(file);
    } else if (target == "psins_attitude") {
      calib::read_psins_attitude_csv(file);
    } else if (target == "nav_trajectory") {
      ims::read_trajectory_csv(file);
    } else if (target == "joint_errors") {
      ident::read_joint_errors_csv(file);
    } else if (target == "frames_json") {
      calib::read_frames_json(file, "kr16");
    } else if (target == "mounting_report") {
      calib::read_mounting_report(file);
    } else if (target == "identification_report") {
      ident::read_identification_report(file);
    } else if (target == "run_record") {
      read_run_record(file);
    } else if (target == "parameter_table") {
      ident::read_parameters_json(file);
    } else if (target == "rsi_datagram") {
      std::ifstream in(file, std::ios::binary);
      parse_rsi_datagram(std::string(std::istreambuf_iterator<char>(in), {}));
    } else if (target == "egm_datagram") {
      std::ifstream in(file, std::ios::binary);
      parse_egm_datagram(std::string(std::istreambuf_iterator<char>(in), {}));
    } else if (target == "yaml_configs") {
      std::ifstream in(file, std::ios::binary);
      parse_yaml_configs(std::string(std::istreambuf_iterator<char>(in), {}));
      // The scenario loader resolves the files it names relative to its own: from the file.
      try {
        sim::load_scenario(file);
      } catch (const InputError&) {
      }
    } else {
      throw std::logic_error("no fuzz target '" + std::string(target) + "'");
    }
  } catch (const InputError&) {
  }
}

}  // namespace imscal::fuzz
