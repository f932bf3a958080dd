#pragma once
// A minimal IPv4 UDP socket (POSIX), private to hw: the base protocol's transport.
#include <netinet/in.h>

#include <cstdint>
#include <string>
#include <vector>

namespace sketchnav::drivers::net {

struct Endpoint {
  sockaddr_in addr{};
  std::string host() const;  // dotted quad
  int port() const;
  std::string str() const { return host() + ":" + std::to_string(port()); }
  bool sameHost(const Endpoint& o) const { return addr.sin_addr.s_addr == o.addr.sin_addr.s_addr; }
  bool operator==(const Endpoint& o) const {
    return sameHost(o) && addr.sin_port == o.addr.sin_port;
  }
  bool isLoopback() const;
  /// Resolves a host name or dotted quad (no DNS broadcast: getaddrinfo, IPv4 only).
  /// Throws InputError naming `what` when it cannot be resolved.
  static Endpoint resolve(const std::string& host, int port, const std::string& what);
};

class UdpSocket {
 public:
  UdpSocket();  // throws RuntimeError when the OS refuses a socket
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  /// Binds to host:port (port 0: an ephemeral port). Throws RuntimeError naming the address.
  void bind(const Endpoint& local);
  Endpoint local() const;
  /// Best effort: returns false (never throws) when the OS refuses the datagram.
  bool sendTo(const std::vector<std::uint8_t>& data, const Endpoint& to);
  /// Waits up to timeout_s for one datagram; returns its size, 0 on timeout, -1 on error.
  long recvFrom(std::vector<std::uint8_t>& buf, Endpoint& from, double timeout_s);
  void close();

 private:
  int fd_ = -1;
};

}  // namespace sketchnav::drivers::net
