#pragma once
// Comma-separated numbers on the command line (--q, --position, --size, ...), read as scene
// files read numbers, so angles may be written with pi ("--q pi/2,-pi/4").
#include <optional>
#include <string>
#include <vector>

namespace kinograph::tools {

/// The finite numbers of "v1,v2,...", `count` of them when given.
/// @throws CommandFailure (bad input) naming `option` and the offending item or the count.
std::vector<double> parse_number_list(const std::string& text, const std::string& option,
                                      std::optional<std::size_t> count = std::nullopt);

}  // namespace kinograph::tools
