// parse_number_text reads the same language as the reader it replaced (a std::regex for the
// pi expressions, yaml-cpp for everything else), to the bit, with the same exceptions: checked
// on hand-picked texts and on every short string over the characters that matter. The reader
// it replaced is kept here as the oracle.
#include "kinograph/planning/io/number_text.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "kinograph/planning/io/scene.h"

namespace kinograph::planning {
namespace {

std::optional<double> regex_reader(const std::string& text) {
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

// What a reader makes of `text`: a value (by its bits, so -0 and NaN compare), nothing, or the
// exception it throws.
std::string outcome(std::optional<double> (*reader)(const std::string&), const std::string& text) {
  try {
    const std::optional<double> v = reader(text);
    if (!v) return "none";
    if (std::isnan(*v)) return "nan";
    unsigned long long bits = 0;
    std::memcpy(&bits, &*v, sizeof bits);
    return std::to_string(bits);
  } catch (const std::out_of_range&) {
    return "out_of_range";
  } catch (const std::invalid_argument&) {
    return "invalid_argument";
  }
}

void expect_same(const std::string& text) {
  EXPECT_EQ(outcome(parse_number_text, text), outcome(regex_reader, text)) << "'" << text << "'";
}

TEST(NumberText, HandPickedTextsReadAsBefore) {
  for (const char* text :
       {"0", "-0", "1", "+1", "1.5", "-1.5", ".5", "-.5", "5.", "1e3", "1E-3", "1e+3", "-1.5e-3",
        "1e", "1e+", "1.5.2", "..5", "1e309", "-1e309", "1e-400", "4.9e-324", "2.2250738585072014e-308",
        "0.1000000000000000055511151231257827", "123456789012345678901234567890", "007", "0x10",
        "1_000", " 1", "1 ", "1\t", "\n1", "", " ", ".", "-", "+", "e5", ".inf", "-.inf", "+.inf",
        ".Inf", ".INF", ".nan", ".NaN", "inf", "nan", "infinity", "NaN", "pi", "-pi", "+pi",
        " - pi ", "pi/2", "-pi/2", "2*pi", "2 * pi / 3", "0.5*pi/3", ".5*pi", "5.*pi", "1e2*pi",
        "1e*pi", "pi/2.", "pi/.5", "pi/1e2", "pi/0", "0*pi", "1e999*pi", "1e-999*pi", "pi/1e-999",
        "pi/" "1" "0000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "pie", "api", "pi pi", "2pi", "2*", "*pi", "pi*2", "--pi", "+-pi", "- -1", "1,5", "1.5f",
        "true", "~", "null", "٣", "\xef\xbc\x91"}) {
    expect_same(text);
  }
}

// Every string of up to 5 characters over the ones that matter, and random longer ones.
TEST(NumberText, EveryShortStringReadsAsBefore) {
  const std::string alphabet = "09.e-+*/pi \t";
  std::vector<std::string> texts = {""};
  for (std::size_t begin = 0, length = 1; length <= 5; ++length) {
    const std::size_t end = texts.size();
    for (std::size_t i = begin; i < end; ++i) {
      for (const char c : alphabet) texts.push_back(texts[i] + c);
    }
    begin = end;
  }
  std::mt19937 rng(7);
  const std::string wide = alphabet + "123456789E.inafINAF_x";
  for (int i = 0; i < 20000; ++i) {
    std::string t(6 + rng() % 10, ' ');
    for (char& c : t) c = wide[rng() % wide.size()];
    texts.push_back(t);
  }
  for (const std::string& t : texts) {
    if (outcome(parse_number_text, t) != outcome(regex_reader, t)) {
      expect_same(t);
      return;  // one is enough to show
    }
  }
}

// The scene reader's message for a text that is no number is what it was.
TEST(NumberText, ASceneNamesTheTextThatIsNoNumber) {
  const std::string scene =
      "name: t\nrobot:\n  urdf: robots/rr/rr.urdf\nhorizon: 2*pie\nsteps: 30\nstart:\n  q: [0, 0]\n"
      "goal:\n  q: [1, 1]\n";
  try {
    (void)parse_scene(scene, std::string(KINOGRAPH_SOURCE_DIR) + "/scene.yaml");
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("must be a number, got '2*pie'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kinograph::planning
