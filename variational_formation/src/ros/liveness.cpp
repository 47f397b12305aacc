#include "variational_formation/ros/liveness.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <ros/master.h>

namespace vf {

namespace {

/// host and port of an "http://host:port/" URI.
bool splitUri(const std::string& uri, std::string& host, int& port) {
  const std::string scheme = "http://";
  if (uri.compare(0, scheme.size(), scheme) != 0) return false;
  const std::string rest = uri.substr(scheme.size());
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos) return false;
  host = rest.substr(0, colon);
  try {
    port = std::stoi(rest.substr(colon + 1));
  } catch (const std::exception&) {
    return false;
  }
  return port > 0 && port < 65536;
}

/// A TCP connection to host:port succeeds within timeoutMs.
/// Connects to host:port: Alive if it accepts, Busy if it neither accepts nor refuses within
/// `timeoutMs` (a full listen backlog), NotAnswering if refused (nothing listens: killed).
Liveness accepts(const std::string& host, int port, int timeoutMs) {
  addrinfo hints{}, *found = nullptr;
  hints.ai_socktype = SOCK_STREAM;
  if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    return Liveness::NotAnswering;
  }
  Liveness l = Liveness::NotAnswering;
  for (addrinfo* a = found; a && l != Liveness::Alive; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      l = Liveness::Alive;
    } else if (errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      int error = 0;
      socklen_t size = sizeof error;
      const int ready = poll(&p, 1, timeoutMs);
      if (ready == 0) {
        l = Liveness::Busy;
      } else if (ready == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) == 0 && error == 0) {
        l = Liveness::Alive;
      }
    }
    close(fd);
  }
  freeaddrinfo(found);
  return l;
}

}  // namespace

Liveness nodeLiveness(const std::string& fullName) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = fullName;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) {
    // The master said "unknown node" (a status code in its answer), or did not answer at all.
    return response.getType() == XmlRpc::XmlRpcValue::TypeArray ? Liveness::NotRegistered : Liveness::Busy;
  }
  std::string host;
  int port = 0;
  if (payload.getType() != XmlRpc::XmlRpcValue::TypeString || !splitUri(static_cast<std::string>(payload), host, port)) {
    return Liveness::NotAnswering;
  }
  return accepts(host, port, 500);
}

const char* describe(Liveness liveness) {
  switch (liveness) {
    case Liveness::Alive: return "alive";
    case Liveness::NotRegistered: return "not registered with the master";
    case Liveness::NotAnswering: return "registered but its process does not answer (killed?)";
    case Liveness::Busy: return "it or the master is too busy to answer; not taken as gone";
  }
  return "?";
}

}  // namespace vf
