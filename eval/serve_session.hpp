#pragma once
// The session behind `imscal serve`: the parameter table (ident/parameter_table_io.hpp) and, where
// the protocol or the table needs it, the program's desired path with the model torque along it
// (eval/model_torque.hpp), made into a datagram session of the online bridge: KUKA RSI
// corrections (online/rsi_session.hpp) or ABB EGM position guidance along the path
// (online/egm_session.hpp, decision 0033). What the table cannot be served with is refused here,
// before a socket is bound, as InputError naming the file and the field.
#include <Eigen/Core>
#include <memory>
#include <string>

#include "core/units.hpp"
#include "ident/parameter_table.hpp"
#include "online/datagram_session.hpp"
#include "online/egm_session.hpp"
#include "online/rsi_session.hpp"

namespace imscal::eval {

enum class ServeProtocol { kRsi, kEgm };

struct ServeSessionOptions {
  ServeProtocol protocol = ServeProtocol::kRsi;
  std::string table_file;  // parameters.json (imscal identify)
  // The program's desired path (a robot log: q_desired and payload per sample); empty: none.
  // RSI follows it by IPOC (needed by tables with a preview or the model torque); EGM streams it.
  std::string path_file;
  bool path_clock_from_first_datagram = false;  // online/path_follower.hpp ("stream" clock)
  // The rigid-body model of the model-torque input (robot file; empty: none) and gravity in the
  // robot base R [m/s^2]; the robot file's joint limits check the path too (decision 0034).
  std::string robot_file;
  Eigen::Vector3d gravity_in_base_m_s2{0.0, 0.0, -kStandardGravity_m_s2};
  online::RsiSessionOptions rsi;  // its cycle_s and late_after_s are set from the fields below
  online::EgmSessionOptions egm;  // likewise; its payload_kg from rsi.payload_kg
  double cycle_s = 0.004;         // the controller's cycle [s]
  double late_after_s = 0.0;      // > 0: a datagram this much later than the cycle is a fault [s]
  double offset_tolerance_rad = 0.0;  // supervisor tolerance per joint; 0: the table's envelope
  double max_setpoint_speed_rad_s = 1000.0 * kRadPerDeg;  // a faster set-point change is a jump
  // With a path the precontrol is fed this many table cycles beyond the table's preview: the
  // delay of its smoother (2 tau = 8 ms), as `imscal verify` does (eval/verification.hpp).
  int look_ahead_cycles = 4;
};

struct ServeSession {
  ident::ParameterTable table;
  std::unique_ptr<online::DatagramSession> session;
  ServeProtocol protocol = ServeProtocol::kRsi;
};

// The table read and its datagram session made; InputError (file, field) for a table the protocol
// cannot serve, a missing or unusable path, or a model torque without its robot file.
ServeSession open_serve_session(const ServeSessionOptions& options);

// Logs the session's queued faults (warnings: malformed datagrams, counter faults) and the
// precontrol's supervisor events (info), emptying both queues; not from the real-time loop.
void log_serve_events(online::DatagramSession& session, ServeProtocol protocol);

}  // namespace imscal::eval
