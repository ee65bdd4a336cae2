// horus topic list / info / echo / hz / bw / pub (topic_cmd.cpp).
#pragma once

#include <atomic>
#include <string>

namespace horus::tools {

// Where the topic commands look for topics this host lacks (the fleet's hosts).
struct Lookup {
  std::string transport;  // --backend, for the fleet
  int wait_ms = 1500;
};

int cmd_list(const std::string& ns, bool json, bool verbose, const Lookup& lookup, bool local_only, bool all,
             const std::atomic<bool>& stop);
int cmd_info(const std::string& ns, const std::string& name, const Lookup& lookup, const std::atomic<bool>& stop);
int cmd_echo(const std::string& ns, const std::string& name, const Lookup& lookup, bool json, long count,
             double timeout_s, const std::atomic<bool>& stop);
int cmd_hz(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s,
           const std::atomic<bool>& stop);
int cmd_bw(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s,
           const std::atomic<bool>& stop);
int cmd_pub(const std::string& ns, const std::string& name, const std::string& type, const std::string& text,
            const Lookup& lookup, double rate_hz, long count, const std::atomic<bool>& stop);

}  // namespace horus::tools
