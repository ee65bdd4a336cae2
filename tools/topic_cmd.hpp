// horus topic list / info / echo / hz / bw / pub (topic_cmd.cpp).
#pragma once

#include <atomic>
#include <chrono>
#include <string>

namespace horus::tools {

// Where the topic commands look for topics this host lacks (the fleet's hosts).
struct Lookup {
  std::string transport;  // --backend, for the fleet
  int wait_ms = 1500;
  // How long a command that reads a topic (echo, hz, bw) waits for a topic that does not exist
  // yet, here or on another host: --wait when given, else echo's --timeout; 0: it must exist now
  // (or be announced within wait_ms).
  std::chrono::milliseconds appear_wait{0};
  // list and info: how long the topics' sent counts are watched for their rates (--window).
  std::chrono::milliseconds rate_window{1000};
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
