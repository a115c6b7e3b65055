// `imscal serve`: the precontrol (ident/precontrol.hpp) online behind KUKA RSI or ABB EGM: binds a
// UDP port, answers every controller datagram (online/udp_server.hpp) with the joint corrections
// of a parameter table, the IPOC echoed (RSI: online/rsi_session.hpp), or with the program's path
// plus the corrections, the seqno echoed (EGM position guidance: online/egm_session.hpp), and
// logs every fault and supervisor event. Runs until interrupted (SIGINT/SIGTERM) or, with
// --idle-timeout-s, until the controller stops sending.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <memory>
#include <stdexcept>

#include "core/input_error.hpp"
#include "eval/serve_session.hpp"
#include "online/rsi_session.hpp"
#include "online/udp_server.hpp"
#include "online/udp_socket.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {
namespace online = imscal::online;

std::atomic<bool> g_stop{false};

extern "C" void request_stop(int) {
  g_stop = true;
}

struct ServeArgs {
  std::string protocol = "rsi", mode = "absolute", bind = "0.0.0.0";
  imscal::tools::ModelTorqueOption model_torque;  // for tables with the model-torque input
  int port = 0;
  imscal::eval::ServeSessionOptions session;
  double cycle_ms = 4.0, late_ms = 0.0, idle_timeout_s = 0.0;
  double max_setpoint_speed_deg_s = 1000.0;
  std::string path_clock = "motion";  // online/path_follower.hpp: "motion" or "stream"
};

// The library session's options from the command line's.
imscal::eval::ServeSessionOptions session_options(const ServeArgs& args) {
  imscal::eval::ServeSessionOptions o = args.session;
  o.protocol = args.protocol == "egm" ? imscal::eval::ServeProtocol::kEgm
                                      : imscal::eval::ServeProtocol::kRsi;
  o.rsi.mode = args.mode == "increment" ? online::RsiCorrectionMode::kIncrement
                                        : online::RsiCorrectionMode::kAbsolute;
  o.path_clock_from_first_datagram = args.path_clock == "stream";
  o.robot_file = args.model_torque.robot;
  const std::vector<double>& g = args.model_torque.gravity_m_s2;
  o.gravity_in_base_m_s2 = Eigen::Vector3d(g[0], g[1], g[2]);
  o.cycle_s = args.cycle_ms * 1e-3;
  o.late_after_s = args.late_ms * 1e-3;
  o.max_setpoint_speed_rad_s = args.max_setpoint_speed_deg_s * M_PI / 180.0;
  return o;
}

void run(const ServeArgs& args) {
  const imscal::eval::ServeSession served = imscal::eval::open_serve_session(session_options(args));
  online::DatagramSession& session = *served.session;
  const bool egm = args.protocol == "egm";
  try {
    (void)online::udp_peer(args.bind, 0);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError("--bind", 0, "", e.what());
  }
  online::UdpSocket socket(args.bind, static_cast<std::uint16_t>(args.port));
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  spdlog::info("serve: {} on {}:{}, {}, cycle {} ms, table {} ({})", egm ? "EGM" : "RSI", args.bind,
               socket.port(),
               egm ? std::string("position guidance along ") + args.session.path_file
                   : args.mode + " corrections",
               args.cycle_ms, args.session.table_file, served.table.robot);
  online::UdpServerOptions options;
  options.idle_timeout_s = args.idle_timeout_s;
  const online::UdpServerStats stats = online::serve_udp(socket, session, g_stop, options, [&] {
    imscal::eval::log_serve_events(session, served.protocol);
  });
  imscal::eval::log_serve_events(session, served.protocol);
  spdlog::info("serve: {} datagrams, {} answered, {} not answered", stats.datagrams, stats.answered,
               stats.not_answered);
}

imscal::tools::CommandRegistration registration{
    "serve",
    "Serve the precontrol online to a robot controller: KUKA RSI (UDP, XML) or ABB EGM (UDP, "
    "protocol buffers)",
    [](CLI::App& sub) {
      auto args = std::make_shared<ServeArgs>();
      sub.add_option("--protocol", args->protocol, "rsi (default) or egm")
          ->check(CLI::IsMember({"rsi", "egm"}));
      sub.add_option("--table", args->session.table_file, "parameters.json (imscal identify)")
          ->required();
      sub.add_option("--port", args->port, "UDP port the controller sends to")
          ->required()
          ->check(CLI::Range(0, 65535));
      sub.add_option("--bind", args->bind, "local IPv4 address to bind (default all)");
      sub.add_option("--mode", args->mode, "AKorr as the RSI configuration sums it")
          ->check(CLI::IsMember({"absolute", "increment"}));
      sub.add_option("--path", args->session.path_file,
                     "the program's desired path (robot.csv): RSI follows it by IPOC (needed by "
                     "tables with a preview or the model torque); EGM streams it (required)");
      sub.add_option("--start-tolerance-rad", args->session.egm.start_tolerance_rad,
                     "EGM: the robot is at the path's first pose within this, per joint")
          ->check(CLI::PositiveNumber);
      sub.add_option("--track-tolerance-rad", args->session.egm.track_tolerance_rad,
                     "EGM: a measured joint farther from its target is a fault")
          ->check(CLI::PositiveNumber);
      args->model_torque.add_to(sub);
      sub.add_option(
             "--look-ahead-cycles", args->session.look_ahead_cycles,
             "with --path: table cycles fed ahead beyond the preview (default 4, as verify)")
          ->check(CLI::Range(0, 32));
      sub.add_option("--path-clock", args->path_clock,
                     "with --path: start its clock at the motion from its start pose, or with the "
                     "stream's first datagram (a path recorded from RSI_ON)")
          ->check(CLI::IsMember({"motion", "stream"}));
      sub.add_option("--robot-type", args->session.rsi.robot_type,
                     "Type attribute of <Rob> expected (default: any)");
      sub.add_option("--sensor-type", args->session.rsi.sensor_type,
                     "Type attribute of the answer's <Sen>");
      sub.add_option("--cycle-ms", args->cycle_ms, "RSI cycle (4 or 12 ms)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--ipoc-per-cycle", args->session.rsi.ipoc_per_cycle,
                     "IPOC advance per cycle (default 4: milliseconds at 4 ms)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--payload-kg", args->session.rsi.payload_kg,
                     "payload for the operating point")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--late-ms", args->late_ms,
                     "a datagram this much later than the cycle is a fault (0: not checked)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--max-setpoint-speed-deg-s", args->max_setpoint_speed_deg_s,
                     "a faster set-point change is a jump (fault)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--offset-tolerance-rad", args->session.offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint (default: the table's envelope)");
      sub.add_option("--idle-timeout-s", args->idle_timeout_s,
                     "stop when no datagram came for this long (0: run until interrupted)")
          ->check(CLI::NonNegativeNumber);
      sub.callback([args] { run(*args); });
    }};
}  // namespace
