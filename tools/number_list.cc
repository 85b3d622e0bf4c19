#include "tools/number_list.h"

#include <cmath>
#include <sstream>

#include "kinograph/planning/io/number_text.h"
#include "tools/command_registry.h"

namespace kinograph::tools {

std::vector<double> parse_number_list(const std::string& text, const std::string& option,
                                      std::optional<std::size_t> count) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::optional<double> value = planning::parse_number_text(item);
    if (!value || !std::isfinite(*value)) {
      throw CommandFailure(option + ": '" + item + "' is not a finite number");
    }
    values.push_back(*value);
  }
  if (!text.empty() && text.back() == ',') {
    throw CommandFailure(option + ": a value is missing after the last comma");
  }
  if (count && values.size() != *count) {
    throw CommandFailure(option + " needs " + std::to_string(*count) +
                         " comma-separated numbers, got " + std::to_string(values.size()));
  }
  return values;
}

}  // namespace kinograph::tools
