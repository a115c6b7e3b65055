#pragma once
// A controller interface's server (online/udp_server.hpp with an RSI or EGM session) on a loopback
// port in a thread of its own, for the tests and benches that play the controller with
// online/controller_emulator.hpp. The faults and
// the precontrol's events are collected after every answer (outside the cycle) and read after
// finish().
#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "online/egm_session.hpp"
#include "online/rsi_session.hpp"
#include "online/udp_server.hpp"
#include "online/udp_socket.hpp"

namespace imscal::test_support {

class LoopbackServer {
 public:
  explicit LoopbackServer(std::unique_ptr<online::DatagramSession> session)
      : socket_("127.0.0.1", 0), session_(std::move(session)) {
    thread_ = std::thread([this] {
      stats_ = online::serve_udp(socket_, *session_, stop_, online::UdpServerOptions{},
                                 [this] { drain(); });
    });
  }
  // RSI.
  LoopbackServer(const ident::ParameterTable& table, const ident::PrecontrolOptions& precontrol,
                 const online::RsiSessionOptions& options,
                 std::unique_ptr<online::PathFollower> path = nullptr)
      : LoopbackServer(rsi_session(table, precontrol, options, std::move(path))) {}
  // EGM: the server plays `path`, the precontrol fed ahead_s ahead.
  LoopbackServer(const ident::ParameterTable& table, const ident::PrecontrolOptions& precontrol,
                 const online::EgmSessionOptions& options, online::LoadedPath path, double ahead_s)
      : LoopbackServer(egm_session(table, precontrol, options, std::move(path), ahead_s)) {}
  LoopbackServer(const LoopbackServer&) = delete;
  LoopbackServer& operator=(const LoopbackServer&) = delete;
  ~LoopbackServer() { finish(); }

  online::UdpPeer peer() const { return online::udp_peer("127.0.0.1", socket_.port()); }
  // Stops the server; then the collections below are complete.
  void finish() {
    if (!thread_.joinable()) return;
    stop_ = true;
    thread_.join();
  }
  const std::vector<online::SessionFaultEvent>& faults() const { return faults_; }
  const std::vector<ident::PrecontrolEvent>& events() const { return events_; }
  const online::UdpServerStats& stats() const { return stats_; }
  online::DatagramSession& session() { return *session_; }

 private:
  static std::unique_ptr<online::DatagramSession> rsi_session(
      const ident::ParameterTable& table, const ident::PrecontrolOptions& precontrol,
      const online::RsiSessionOptions& options, std::unique_ptr<online::PathFollower> path) {
    std::string why;
    auto session =
        online::RsiSession::create(table, table.robot, precontrol, options, &why, std::move(path));
    if (!session) throw std::invalid_argument("RSI session refused: " + why);
    return session;
  }
  static std::unique_ptr<online::DatagramSession> egm_session(
      const ident::ParameterTable& table, const ident::PrecontrolOptions& precontrol,
      const online::EgmSessionOptions& options, online::LoadedPath path, double ahead_s) {
    std::string why;
    auto session = online::EgmSession::create(table, table.robot, precontrol, options,
                                              std::move(path), ahead_s, &why);
    if (!session) throw std::invalid_argument("EGM session refused: " + why);
    return session;
  }

  void drain() {
    std::array<online::SessionFaultEvent, 16> f{};
    for (int n; (n = session_->read_faults(f.data(), int(f.size()))) > 0;)
      faults_.insert(faults_.end(), f.begin(), f.begin() + n);
    std::array<ident::PrecontrolEvent, 16> e{};
    for (int n; (n = session_->precontrol().read_events(e.data(), int(e.size()))) > 0;)
      events_.insert(events_.end(), e.begin(), e.begin() + n);
  }

  online::UdpSocket socket_;
  std::unique_ptr<online::DatagramSession> session_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  online::UdpServerStats stats_;
  std::vector<online::SessionFaultEvent> faults_;
  std::vector<ident::PrecontrolEvent> events_;
};

}  // namespace imscal::test_support
