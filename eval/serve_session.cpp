#include "eval/serve_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "eval/model_torque.hpp"
#include "ident/parameter_table_io.hpp"
#include "online/path_follower.hpp"
#include "robot/robot_log.hpp"

namespace imscal::eval {
namespace {

bool takes_model_torque(const ident::ParameterTable& table) {
  return std::find(table.extra_inputs.begin(), table.extra_inputs.end(),
                   ident::TableInput::kModelTorque) != table.extra_inputs.end();
}

// The model torque along the path [sample][joint] for a table whose models take it.
std::vector<std::array<double, online::kPathJoints>> torque_along(
    const ServeSessionOptions& o, const ident::ParameterTable& table, const calib::RobotLog& log,
    const std::vector<std::vector<double>>& q_rad, const std::vector<double>& payload_kg) {
  const ModelTorqueSource model = with_table_links(
      load_model_torque_source(o.robot_file, o.gravity_in_base_m_s2, log.robot_name, o.path_file,
                               o.table_file, "extra_inputs"),
      table, o.table_file);
  const std::size_t n = payload_kg.size();
  const std::vector<std::pair<std::size_t, std::size_t>> whole{{0, n}};
  const auto torque = model_torques_along(model, log.cycle_s, q_rad, payload_kg, whole);
  std::vector<std::array<double, online::kPathJoints>> out(n);
  for (std::size_t k = 0; k < n; ++k)
    for (int j = 0; j < online::kPathJoints; ++j)
      out[k][std::size_t(j)] = torque[std::size_t(j)][k];
  return out;
}

// The robot program's desired path (decision 0024), with the model torque along it when the
// table's models take it (as `imscal compensate`).
online::LoadedPath load_path(const ServeSessionOptions& o, const ident::ParameterTable& table) {
  const calib::RobotLog log =
      calib::read_robot_log_csv(o.path_file, table.robot, "the parameter table " + o.table_file);
  if (!o.robot_file.empty())
    calib::check_robot_log_joint_limits(log, o.path_file,
                                        calib::load_robot_description(o.robot_file));
  online::LoadedPath path;
  path.cycle_s = log.cycle_s;
  const std::size_t n = log.samples.size();
  std::vector<std::vector<double>> q(calib::kJointCount, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    std::array<double, online::kPathJoints> sample{};
    for (int j = 0; j < online::kPathJoints; ++j) {
      sample[std::size_t(j)] = log.samples[k].q_desired_rad[j];
      q[std::size_t(j)][k] = sample[std::size_t(j)];
    }
    path.q_rad.push_back(sample);
    path.payload_kg.push_back(log.samples[k].payload_kg);
  }
  if (takes_model_torque(table)) path.torque_nm = torque_along(o, table, log, q, path.payload_kg);
  return path;
}

// How far ahead of the set-point the precontrol is fed [s].
double ahead_s(const ServeSessionOptions& o, const ident::ParameterTable& table) {
  return (table.preview_cycles + o.look_ahead_cycles) * table.sample_time_s;
}

// RSI: the path followed by the controller's IPOC.
std::unique_ptr<online::PathFollower> follow_path(const ServeSessionOptions& o,
                                                  const ident::ParameterTable& table) {
  online::LoadedPath path = load_path(o, table);
  try {
    online::PathFollowerOptions follow;
    follow.clock_from_first_datagram = o.path_clock_from_first_datagram;
    return std::make_unique<online::PathFollower>(std::move(path), o.cycle_s, ahead_s(o, table),
                                                  follow);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.path_file, 0, "cycle_s", e.what());
  }
}

// Without a loaded path the table must not need one: RSI sends the current set-point only.
void check_servable_without_path(const std::string& file, const ident::ParameterTable& table) {
  if (table.preview_cycles > 0) {
    throw InputError(
        file, 0, "preview_cycles",
        "the table needs the desired path " + std::to_string(table.preview_cycles) +
            " cycles ahead, which RSI does not send: give the program's path (--path robot.csv) "
            "or serve a table without preview (docs/decisions/0024)");
  }
  if (takes_model_torque(table)) {
    throw InputError(file, 0, "extra_inputs",
                     "the table's models take the model torque along the desired path: "
                     "give the program's path (--path robot.csv) and --robot");
  }
}

ident::PrecontrolOptions precontrol_options(const ServeSessionOptions& o) {
  ident::PrecontrolOptions precontrol;
  if (o.offset_tolerance_rad > 0.0) precontrol.offset_tolerance_rad.fill(o.offset_tolerance_rad);
  precontrol.max_input_speed_rad_s = o.max_setpoint_speed_rad_s;
  return precontrol;
}

std::unique_ptr<online::DatagramSession> rsi_session(const ServeSessionOptions& o,
                                                     const ident::ParameterTable& table) {
  std::unique_ptr<online::PathFollower> path;
  if (o.path_file.empty()) {
    check_servable_without_path(o.table_file, table);
  } else {
    path = follow_path(o, table);
  }
  online::RsiSessionOptions rsi = o.rsi;
  rsi.cycle_s = o.cycle_s;
  rsi.late_after_s = o.late_after_s;
  std::string why;
  auto session = online::RsiSession::create(table, table.robot, precontrol_options(o), rsi, &why,
                                            std::move(path));
  if (!session) throw InputError(o.table_file, 0, "", "cannot serve this table: " + why);
  return session;
}

// EGM position guidance: the server plays the program's path (decision 0033).
std::unique_ptr<online::DatagramSession> egm_session(const ServeSessionOptions& o,
                                                     const ident::ParameterTable& table) {
  if (o.path_file.empty())
    throw InputError("--path", 0, "",
                     "EGM position guidance streams the program's desired path: give it "
                     "(--path robot.csv)");
  online::EgmSessionOptions egm = o.egm;
  egm.cycle_s = o.cycle_s;
  egm.late_after_s = o.late_after_s;
  egm.payload_kg = o.rsi.payload_kg;
  std::string why;
  auto session = online::EgmSession::create(table, table.robot, precontrol_options(o), egm,
                                            load_path(o, table), ahead_s(o, table), &why);
  if (!session) throw InputError(o.path_file, 0, "", "cannot serve this path: " + why);
  return session;
}

}  // namespace

ServeSession open_serve_session(const ServeSessionOptions& options) {
  ServeSession out;
  out.protocol = options.protocol;
  out.table = ident::read_parameters_json(options.table_file);
  out.session = options.protocol == ServeProtocol::kEgm ? egm_session(options, out.table)
                                                        : rsi_session(options, out.table);
  return out;
}

void log_serve_events(online::DatagramSession& session, ServeProtocol protocol) {
  const bool egm = protocol == ServeProtocol::kEgm;
  std::array<online::SessionFaultEvent, 32> faults{};
  const char* counter = egm ? "EGM: seqno" : "RSI: IPOC";
  for (int n; (n = session.read_faults(faults.data(), int(faults.size()))) > 0;) {
    for (int i = 0; i < n; ++i) {
      const online::SessionFaultEvent& f = faults[std::size_t(i)];
      if (f.fault == online::SessionFault::kMalformed) {
        spdlog::warn("{}: malformed datagram refused: {}", egm ? "EGM" : "RSI",
                     egm ? online::to_string(static_cast<online::EgmParseError>(f.detail))
                         : online::to_string(static_cast<online::RsiParseError>(f.detail)));
      } else {
        spdlog::warn("{} {}: {} (value {})", counter, f.counter, online::to_string(f.fault),
                     f.value);
      }
    }
  }
  std::array<ident::PrecontrolEvent, 32> events{};
  for (int n; (n = session.precontrol().read_events(events.data(), int(events.size()))) > 0;) {
    for (int i = 0; i < n; ++i) {
      const ident::PrecontrolEvent& e = events[std::size_t(i)];
      spdlog::info("precontrol: cycle {}: {}: {} (value {})", e.cycle,
                   e.joint < 0 ? std::string("all joints") : fmt::format("A{}", e.joint + 1),
                   ident::to_string(e.cause), e.value);
    }
  }
}

}  // namespace imscal::eval
