// `imscal serve` end to end: the command serves a parameter table on a loopback port; the
// controller emulator (online/controller_emulator.hpp) drives it, with a malformed datagram
// and a lost one among 1000; every datagram sent in order is answered, the command logs the
// faults and stops after its idle timeout with exit code 0. A table the interface cannot feed
// (with preview) without the program's path is refused with exit code 2, naming the field; with
// the path (--path robot.csv) it is served, following the path by the IPOC. With --protocol egm
// the command plays the path to an emulated ABB controller (and refuses to run without it).
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "ident/parameter_table_io.hpp"
#include "online/controller_emulator.hpp"
#include "online/egm_codec.hpp"
#include "robot/robot_log.hpp"
#include "tests/support/lag_table.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::online {
namespace {

using test_support::read_text;
using test_support::run_imscal;

class ServeCli : public test_support::ScratchDirTest {};

ident::ParameterTable lag_table() {
  return test_support::lag_table(-0.9, 0.1);
}

// A free port (the system's pick, released again: another process could take it meanwhile,
// which on a test machine it does not).
std::uint16_t free_port() {
  UdpSocket probe("127.0.0.1", 0);
  return probe.port();
}

TEST_F(ServeCli, ServesTheControllerAndLogsItsFaults) {
  ident::write_parameters_json(dir_ / "table.json", lag_table());
  const std::uint16_t port = free_port();
  int exit_code = -1;
  std::thread server([&] {
    exit_code = run_imscal("serve --table " + (dir_ / "table.json").string() +
                               " --bind 127.0.0.1 --port " + std::to_string(port) +
                               " --robot-type KUKA --offset-tolerance-rad 0.05 --idle-timeout-s 3",
                           dir_ / "serve.log");
  });
  UdpSocket controller("127.0.0.1", 0);
  const UdpPeer peer = udp_peer("127.0.0.1", port);
  // Wait for the command to listen: a probe datagram until one is answered (cycle 0).
  std::array<char, 1024> buffer{};
  bool up = false;
  for (int attempt = 0; attempt < 100 && !up; ++attempt) {
    const int n = write_rsi_robot_datagram("KUKA", {}, 1000, buffer.data(), int(buffer.size()));
    ASSERT_TRUE(controller.send(buffer.data(), n, peer));
    UdpPeer from;
    up = controller.receive(buffer.data(), int(buffer.size()), 0.1, &from) > 0;
  }
  ASSERT_TRUE(up) << read_text(dir_ / "serve.log");
  std::vector<std::array<double, kRsiAxes>> setpoint(1000);
  for (std::size_t k = 0; k < setpoint.size(); ++k)
    for (int a = 0; a < kRsiAxes; ++a) setpoint[k][std::size_t(a)] = 0.1 * std::sin(0.004 * k);
  EmulatorOptions options;
  options.first_ipoc = 1004;
  options.answer_timeout_s =
      2.0;  // a stalled server (loaded machine) is not a missed answer  // after the probe's
  options.faults = {{300, InjectedFault::kMalformed}, {600, InjectedFault::kDrop}};
  const EmulatorRun run = emulate_controller(controller, peer, setpoint, options);
  server.join();
  const std::string log = read_text(dir_ / "serve.log");
  EXPECT_EQ(exit_code, 0) << log;
  EXPECT_EQ(run.missed, 0u);
  EXPECT_NE(log.find("malformed datagram refused"), std::string::npos) << log;
  EXPECT_NE(log.find("lost datagrams"), std::string::npos) << log;
  EXPECT_NE(log.find("engaged"), std::string::npos) << log;
  // 1 probe + 999 sent + 1 malformed.
  EXPECT_NE(log.find("1001 datagrams, 1000 answered, 1 not answered"), std::string::npos) << log;
}

// The program of the path tests: rest for 1 s at 0, then every joint swings 0.1 (1 - cos) rad
// over 3 s; a robot log at 2 ms, served at the controller's cycle of 4 ms.
calib::RobotLog swing_program() {
  calib::RobotLog path;
  path.robot_name = "kr16";
  path.cycle_s = 0.002;
  for (int k = 0; k < 2500; ++k) {
    const double t = k * 0.002, s_t = std::max(0.0, t - 1.0);
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(6, 0.1 * (1.0 - std::cos(2.0 * s_t)));
    path.samples.push_back({t, 0.0, q, q});
  }
  return path;
}

TEST_F(ServeCli, PlaysTheLoadedPathToAnEgmController) {
  const calib::RobotLog path = swing_program();
  calib::write_robot_log_csv(dir_ / "robot.csv", path, Overwrite::kAllow);
  ident::ParameterTable table = lag_table();
  table.model_form = ident::TableForm::kInverse;
  table.preview_cycles = 20;
  ident::write_parameters_json(dir_ / "preview.json", table);
  const std::uint16_t port = free_port();
  int exit_code = -1;
  std::thread server([&] {
    exit_code =
        run_imscal("serve --protocol egm --table " + (dir_ / "preview.json").string() + " --path " +
                       (dir_ / "robot.csv").string() + " --bind 127.0.0.1 --port " +
                       std::to_string(port) + " --offset-tolerance-rad 0.05 --idle-timeout-s 3",
                   dir_ / "serve.log");
  });
  // Until the server is up: a robot away from the path's start (held there, the path not
  // started).
  UdpSocket controller("127.0.0.1", 0);
  const UdpPeer peer = udp_peer("127.0.0.1", port);
  std::array<char, 1024> buffer{};
  EgmCodec codec;
  EgmRobotDatagram away;
  away.seqno = 1;
  away.feedback_joints = 6;
  away.feedback_deg.fill(5.0);
  bool up = false;
  for (int attempt = 0; attempt < 100 && !up; ++attempt) {
    const int n = codec.write_robot(away, buffer.data(), int(buffer.size()));
    ASSERT_TRUE(controller.send(buffer.data(), n, peer));
    UdpPeer from;
    up = controller.receive(buffer.data(), int(buffer.size()), 0.1, &from) > 0;
    ++away.seqno;
  }
  ASSERT_TRUE(up) << read_text(dir_ / "serve.log");
  std::vector<std::array<double, kRsiAxes>> setpoint;
  for (std::size_t k = 0; k < path.samples.size(); k += 2) {
    std::array<double, kRsiAxes> q{};
    for (int a = 0; a < kRsiAxes; ++a) q[std::size_t(a)] = path.samples[k].q_desired_rad[a];
    setpoint.push_back(q);
  }
  EmulatorOptions options;
  options.protocol = ControllerProtocol::kEgm;
  options.first_ipoc = 1000;
  options.ipoc_per_cycle = 1;
  options.answer_timeout_s = 2.0;  // a stalled server (loaded machine) is not a missed answer
  const EmulatorRun run = emulate_controller(controller, peer, setpoint, options);
  server.join();
  const std::string log = read_text(dir_ / "serve.log");
  EXPECT_EQ(exit_code, 0) << log;
  EXPECT_EQ(run.missed, 0u);
  EXPECT_NE(log.find("not at the path's first pose"), std::string::npos) << log;
  EXPECT_NE(log.find("engaged"), std::string::npos) << log;
  double largest = 0.0;
  for (const auto& c : run.correction_rad) largest = std::max(largest, std::abs(c[0]));
  EXPECT_GT(largest, 1e-4) << log;  // the preview table corrects the swing
  EXPECT_LT(largest, 0.05);         // within the supervisor's tolerance
}

TEST_F(ServeCli, RefusesEgmWithoutThePath) {
  ident::write_parameters_json(dir_ / "table.json", lag_table());
  EXPECT_EQ(
      run_imscal("serve --protocol egm --table " + (dir_ / "table.json").string() + " --port 0",
                 dir_ / "serve.log"),
      2);
  EXPECT_NE(read_text(dir_ / "serve.log").find("--path"), std::string::npos)
      << read_text(dir_ / "serve.log");
}

TEST_F(ServeCli, FollowsALoadedPathForATableWithPreview) {
  const calib::RobotLog path = swing_program();
  calib::write_robot_log_csv(dir_ / "robot.csv", path, Overwrite::kAllow);
  ident::ParameterTable table = lag_table();
  table.model_form = ident::TableForm::kInverse;
  table.preview_cycles = 20;
  ident::write_parameters_json(dir_ / "preview.json", table);
  const std::uint16_t port = free_port();
  int exit_code = -1;
  std::thread server([&] {
    exit_code =
        run_imscal("serve --table " + (dir_ / "preview.json").string() + " --path " +
                       (dir_ / "robot.csv").string() + " --bind 127.0.0.1 --port " +
                       std::to_string(port) + " --offset-tolerance-rad 0.05 --idle-timeout-s 3",
                   dir_ / "serve.log");
  });
  UdpSocket controller("127.0.0.1", 0);
  const UdpPeer peer = udp_peer("127.0.0.1", port);
  std::array<char, 1024> buffer{};
  bool up = false;
  for (int attempt = 0; attempt < 100 && !up; ++attempt) {
    const int n = write_rsi_robot_datagram("KUKA", {}, 1000, buffer.data(), int(buffer.size()));
    ASSERT_TRUE(controller.send(buffer.data(), n, peer));
    UdpPeer from;
    up = controller.receive(buffer.data(), int(buffer.size()), 0.1, &from) > 0;
  }
  ASSERT_TRUE(up) << read_text(dir_ / "serve.log");
  std::vector<std::array<double, kRsiAxes>> setpoint;
  for (std::size_t k = 0; k < path.samples.size(); k += 2) {
    std::array<double, kRsiAxes> q{};
    for (int a = 0; a < kRsiAxes; ++a) q[std::size_t(a)] = path.samples[k].q_desired_rad[a];
    setpoint.push_back(q);
  }
  EmulatorOptions options;
  options.first_ipoc = 1004;
  options.answer_timeout_s = 2.0;  // a stalled server (loaded machine) is not a missed answer
  const EmulatorRun run = emulate_controller(controller, peer, setpoint, options);
  server.join();
  const std::string log = read_text(dir_ / "serve.log");
  EXPECT_EQ(exit_code, 0) << log;
  EXPECT_EQ(run.missed, 0u);
  EXPECT_EQ(log.find("off the loaded path"), std::string::npos) << log;
  EXPECT_NE(log.find("engaged"), std::string::npos) << log;
  double largest = 0.0;
  for (const auto& c : run.correction_rad) largest = std::max(largest, std::abs(c[0]));
  EXPECT_GT(largest, 1e-4) << log;  // the preview table corrects the swing
}

TEST_F(ServeCli, RefusesATableWithPreview) {
  ident::ParameterTable table = lag_table();
  table.model_form = ident::TableForm::kInverse;
  table.preview_cycles = 20;
  ident::write_parameters_json(dir_ / "preview.json", table);
  EXPECT_EQ(run_imscal("serve --table " + (dir_ / "preview.json").string() + " --port 0",
                       dir_ / "serve.log"),
            2);
  EXPECT_NE(read_text(dir_ / "serve.log").find("preview_cycles"), std::string::npos)
      << read_text(dir_ / "serve.log");
}

}  // namespace
}  // namespace imscal::online
