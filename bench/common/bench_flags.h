#pragma once
// The benchmarks' command lines: each program declares its flags once; an unknown flag or a
// flag without its value prints the usage line built from those declarations.
#include <cmath>
#include <exception>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace kinograph::bench {

/// The scenes shipped in the source tree.
inline const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

/// A JSON number, NaN for null (the benchmarks write NaN as null).
inline double json_number(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : std::nan("");
}

/// The flags of one benchmark program: `--name VALUE` options and `--name` switches.
class Flags {
 public:
  explicit Flags(std::string program) : program_(std::move(program)) {}

  /// `--name VALUE`, VALUE handed to `set` (which may throw std::invalid_argument).
  Flags& value(const std::string& name, const std::string& meta,
               std::function<void(const std::string&)> set) {
    flags_.push_back({name, meta, std::move(set)});
    return *this;
  }
  Flags& value(const std::string& name, int* v) {
    return value(name, "N", [v](const std::string& s) { *v = std::stoi(s); });
  }
  Flags& value(const std::string& name, double* v) {
    return value(name, "X", [v](const std::string& s) { *v = std::stod(s); });
  }
  Flags& value(const std::string& name, std::string* v) {
    return value(name, "FILE", [v](const std::string& s) { *v = s; });
  }
  /// `--name` without a value.
  Flags& toggle(const std::string& name, std::function<void()> set) {
    flags_.push_back({name, "", [set = std::move(set)](const std::string&) { set(); }});
    return *this;
  }

  /// Reads argv; false, after printing the usage to stderr, on an unknown flag, a missing value
  /// or a value its flag cannot read.
  bool parse(int argc, char** argv) const {
    for (int i = 1; i < argc; ++i) {
      const Flag* f = find(argv[i]);
      const bool takes_value = f != nullptr && !f->meta.empty();
      if (f == nullptr || (takes_value && i + 1 >= argc)) return usage();
      try {
        f->set(takes_value ? argv[++i] : "");
      } catch (const std::exception&) {
        return usage();
      }
    }
    return true;
  }

 private:
  struct Flag {
    std::string name, meta;
    std::function<void(const std::string&)> set;
  };
  const Flag* find(const std::string& name) const {
    for (const Flag& f : flags_) {
      if (f.name == name) return &f;
    }
    return nullptr;
  }
  bool usage() const {
    std::cerr << "usage: " << program_;
    for (const Flag& f : flags_) {
      std::cerr << " [" << f.name << (f.meta.empty() ? "" : " " + f.meta) << "]";
    }
    std::cerr << "\n";
    return false;
  }

  std::string program_;
  std::vector<Flag> flags_;
};

}  // namespace kinograph::bench
