#include "kinograph/planning/io/number_text.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <regex>

namespace kinograph::planning {

std::optional<double> parse_number_text(const std::string& text) {
  static const std::regex kPi(
      R"(^\s*([+-]?)\s*(?:([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*\*\s*)?pi\s*(?:/\s*([0-9]*\.?[0-9]+))?\s*$)");
  std::smatch m;
  if (std::regex_match(text, m, kPi)) {
    double value = M_PI;
    if (m[2].matched) value *= std::stod(m[2].str());
    if (m[3].matched) value /= std::stod(m[3].str());
    return m[1].str() == "-" ? -value : value;
  }
  double value = 0;
  if (!YAML::convert<double>::decode(YAML::Node(text), value)) return std::nullopt;
  return value;
}

}  // namespace kinograph::planning
