// SPDX-License-Identifier: LGPL-2.1-or-later
// Free UDP ports on 127.0.0.1 for tests that run documented lines with fixed ports.
#pragma once

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <map>
#include <regex>
#include <string>
#include <vector>

namespace pfap::testing {

// UDP ports on 127.0.0.1 that were free a moment ago: each bound to port 0 by the system,
// all held until the last is found (so they differ), then released for the pipelines.
inline std::vector<int> free_udp_ports(size_t n) {
  std::vector<int> sockets;
  std::vector<int> ports;
  for (size_t i = 0; i < n; ++i) {
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = 0;
    socklen_t length = sizeof address;
    if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      ADD_FAILURE() << "cannot bind a UDP socket on 127.0.0.1";
      if (fd >= 0) close(fd);
      break;
    }
    sockets.push_back(fd);
    ports.push_back(ntohs(address.sin_port));
  }
  for (int fd : sockets) close(fd);
  return ports;
}

// Documented ports made free ones: each `port=N` of a line becomes `port=` a free port, the
// same documented port always the same free one, so that the lines of a session still meet.
class FreePorts {
 public:
  std::string operator()(const std::string& line) {
    static const std::regex port("port=([0-9]+)");
    std::string out;
    auto last = line.cbegin();
    for (std::sregex_iterator it(line.begin(), line.end(), port), end; it != end; ++it) {
      out.append(last, (*it)[0].first);
      out += "port=" + std::to_string(free_port(std::stoi((*it)[1].str())));
      last = (*it)[0].second;
    }
    out.append(last, line.cend());
    return out;
  }

 private:
  int free_port(int documented) {
    if (auto it = ports_.find(documented); it != ports_.end()) return it->second;
    const std::vector<int> free = free_udp_ports(1);
    return ports_[documented] = free.empty() ? documented : free[0];
  }

  std::map<int, int> ports_;
};

}  // namespace pfap::testing
