#include "kinograph/planning/io/number_text.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

namespace kinograph::planning {
namespace {

// What ECMAScript's \s is in the C locale.
bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Reads the grammar
//   \s* [+-]? \s* (NUMBER \s* '*' \s*)? pi \s* ('/' \s* DECIMAL)? \s*
// where DECIMAL = [0-9]*\.?[0-9]+ and NUMBER = DECIMAL ([eE][+-]?[0-9]+)?, one character at a
// time: a regex per number made scene and change files slow to read.
class PiExpression {
 public:
  explicit PiExpression(const std::string& text) : text_(text) {}

  std::optional<double> value() {
    skip_spaces();
    bool negative = false;
    if (at('+') || at('-')) negative = text_[i_++] == '-';
    skip_spaces();
    std::optional<std::string_view> factor;
    if (!at_pi()) {
      factor = decimal(/*exponent=*/true);
      if (!factor) return std::nullopt;
      skip_spaces();
      if (!at('*')) return std::nullopt;
      ++i_;
      skip_spaces();
      if (!at_pi()) return std::nullopt;
    }
    i_ += 2;
    skip_spaces();
    std::optional<std::string_view> divisor;
    if (at('/')) {
      ++i_;
      skip_spaces();
      divisor = decimal(/*exponent=*/false);
      if (!divisor) return std::nullopt;
      skip_spaces();
    }
    if (i_ != text_.size()) return std::nullopt;
    // std::stod as before: its range errors (1e999*pi) are the callers' to see.
    double v = M_PI;
    if (factor) v *= std::stod(std::string(*factor));
    if (divisor) v /= std::stod(std::string(*divisor));
    return negative ? -v : v;
  }

 private:
  bool at(char c) const { return i_ < text_.size() && text_[i_] == c; }
  bool at_pi() const { return text_.compare(i_, 2, "pi") == 0; }
  void skip_spaces() {
    while (i_ < text_.size() && is_space(text_[i_])) ++i_;
  }
  bool digit() const { return i_ < text_.size() && is_digit(text_[i_]); }
  // DECIMAL (and its exponent when allowed). A '.' or an exponent that does not complete it
  // cannot be followed by anything the grammar allows, so failing at once matches the regex.
  std::optional<std::string_view> decimal(bool exponent) {
    const std::size_t start = i_;
    while (digit()) ++i_;
    if (at('.')) {
      ++i_;
      if (!digit()) return std::nullopt;
      while (digit()) ++i_;
    } else if (i_ == start) {
      return std::nullopt;
    }
    if (exponent && (at('e') || at('E'))) {
      ++i_;
      if (at('+') || at('-')) ++i_;
      if (!digit()) return std::nullopt;
      while (digit()) ++i_;
    }
    return std::string_view(text_).substr(start, i_ - start);
  }

  const std::string& text_;
  std::size_t i_ = 0;
};

// A plain decimal ("-1.5e3"), read as yaml-cpp would (a stream into a double, i.e. strtod):
// from_chars rounds the same and, on these characters alone, accepts only what strtod reads in
// full. Anything else (a sign '+', ".inf", overflow, underflow to 0) is left to yaml-cpp.
std::optional<double> plain_decimal(const std::string& text) {
  for (const char c : text) {
    if (!is_digit(c) && c != '.' && c != 'e' && c != 'E' && c != '-' && c != '+') {
      return std::nullopt;
    }
  }
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || ptr != end) return std::nullopt;
  return value;
}

}  // namespace

std::optional<double> parse_number_text(const std::string& text) {
  if (std::optional<double> v = plain_decimal(text)) return v;
  if (text.find("pi") != std::string::npos) {
    if (std::optional<double> v = PiExpression(text).value()) return v;
  }
  double value = 0;
  if (!YAML::convert<double>::decode(YAML::Node(text), value)) return std::nullopt;
  return value;
}

}  // namespace kinograph::planning
