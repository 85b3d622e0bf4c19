#pragma once
// A directory of one test's own. mkdtemp makes its name unique, so suites that run at the same
// time (ctest -j, two checkouts, CI beside a developer) never share or delete each other's files.
#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace kinograph::test_support {

/// A fresh directory `<tmp>/<prefix>.XXXXXX`, removed with its contents by the destructor.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "kinograph_test") : path_(make(prefix)) {}
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// Makes a fresh directory `<tmp>/<prefix>.XXXXXX` that the caller removes (a fixture's
  /// TearDown). @throws std::runtime_error when it cannot be made.
  static std::filesystem::path make(const std::string& prefix) {
    std::string name = (std::filesystem::temp_directory_path() / (prefix + ".XXXXXX")).string();
    if (mkdtemp(name.data()) == nullptr) throw std::runtime_error("mkdtemp failed: " + name);
    return name;
  }
  /// A path inside the directory.
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace kinograph::test_support
