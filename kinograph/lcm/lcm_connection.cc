#include "kinograph/lcm/lcm_connection.h"

#include <algorithm>
#include <cctype>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>

namespace kinograph::messages {

std::unique_ptr<lcm::LCM> open_lcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error("LCM could not start on \"" +
                             (url.empty() ? std::string("default URL") : url) +
                             "\" (for udpm a multicast route is needed, see docs/network.md)");
  }
  return lcm;
}

std::string default_channel_prefix(const std::string& robot_name) {
  std::string s = robot_name;
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

std::string channel_prefix_or_default(const std::string& prefix, const std::string& robot_name) {
  return prefix.empty() ? default_channel_prefix(robot_name) : prefix;
}

lcm::LCM* shared_or_open(lcm::LCM* shared, const std::string& url,
                         std::unique_ptr<lcm::LCM>& owned) {
  if (shared != nullptr) return shared;
  owned = open_lcm(url);
  return owned.get();
}

}  // namespace kinograph::messages
