#pragma once
// An RSI server (online/rsi_server.hpp) on a loopback port in a thread of its own, for the tests
// and benches that play the controller with online/rsi_controller_emulator.hpp. The faults and
// the precontrol's events are collected after every answer (outside the cycle) and read after
// finish().
#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "online/rsi_server.hpp"
#include "online/rsi_session.hpp"
#include "online/udp_socket.hpp"

namespace imscal::test_support {

class RsiLoopbackServer {
 public:
  RsiLoopbackServer(const ident::ParameterTable& table, const ident::PrecontrolOptions& precontrol,
                    const online::RsiSessionOptions& options,
                    std::unique_ptr<online::PathFollower> path = nullptr)
      : socket_("127.0.0.1", 0) {
    std::string why;
    session_ =
        online::RsiSession::create(table, table.robot, precontrol, options, &why, std::move(path));
    if (!session_) throw std::invalid_argument("RSI session refused: " + why);
    thread_ = std::thread([this] {
      stats_ = online::serve_rsi(socket_, *session_, stop_, online::RsiServerOptions{},
                                 [this] { drain(); });
    });
  }
  RsiLoopbackServer(const RsiLoopbackServer&) = delete;
  RsiLoopbackServer& operator=(const RsiLoopbackServer&) = delete;
  ~RsiLoopbackServer() { finish(); }

  online::UdpPeer peer() const { return online::udp_peer("127.0.0.1", socket_.port()); }
  // Stops the server; then the collections below are complete.
  void finish() {
    if (!thread_.joinable()) return;
    stop_ = true;
    thread_.join();
  }
  const std::vector<online::RsiFaultEvent>& faults() const { return faults_; }
  const std::vector<ident::PrecontrolEvent>& events() const { return events_; }
  const online::RsiServerStats& stats() const { return stats_; }
  online::RsiSession& session() { return *session_; }

 private:
  void drain() {
    std::array<online::RsiFaultEvent, 16> f{};
    for (int n; (n = session_->read_faults(f.data(), int(f.size()))) > 0;)
      faults_.insert(faults_.end(), f.begin(), f.begin() + n);
    std::array<ident::PrecontrolEvent, 16> e{};
    for (int n; (n = session_->precontrol().read_events(e.data(), int(e.size()))) > 0;)
      events_.insert(events_.end(), e.begin(), e.begin() + n);
  }

  online::UdpSocket socket_;
  std::unique_ptr<online::RsiSession> session_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  online::RsiServerStats stats_;
  std::vector<online::RsiFaultEvent> faults_;
  std::vector<ident::PrecontrolEvent> events_;
};

}  // namespace imscal::test_support
