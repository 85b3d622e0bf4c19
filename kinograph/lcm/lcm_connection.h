#pragma once
// What every kinograph LCM node does first: open its LCM connection and name its channels.
#include <memory>
#include <string>

namespace lcm {
class LCM;
}  // namespace lcm

namespace kinograph::messages {

/// Opens LCM on `url` (empty = $LCM_DEFAULT_URL, else LCM's default multicast group).
/// @throws std::runtime_error naming the URL when LCM cannot start (udpm needs a multicast
///   route, docs/network.md).
std::unique_ptr<lcm::LCM> open_lcm(const std::string& url);

/// A robot's default channel prefix: its URDF name upper-cased ("iiwa14" → "IIWA14").
std::string default_channel_prefix(const std::string& robot_name);

/// The prefix a node uses: `prefix` when given, else the robot's default.
std::string channel_prefix_or_default(const std::string& prefix, const std::string& robot_name);

/// A node's connection: `shared` when given, else one of its own on `url`, kept in `owned`.
/// @throws std::runtime_error as open_lcm.
lcm::LCM* shared_or_open(lcm::LCM* shared, const std::string& url,
                         std::unique_ptr<lcm::LCM>& owned);

}  // namespace kinograph::messages
