#pragma once
// Numbers as people write them in scene files and on the command line: a decimal, or an angle
// written with pi ("pi", "-pi/2", "2*pi", "0.5*pi/3"). One reader for both, so they agree.
#include <optional>
#include <string>

namespace kinograph::planning {

/// The value of `text` as a scene file reads a number (YAML's syntax, so ".inf" is infinity,
/// or a pi expression); nullopt when it is neither. NaN is returned as NaN for the caller to
/// refuse in its own terms.
std::optional<double> parse_number_text(const std::string& text);

}  // namespace kinograph::planning
