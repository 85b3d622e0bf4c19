#include "kinograph/planning/io/data_dir.h"

#include <cstdlib>
#include <optional>
#include <system_error>

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;

std::optional<fs::path> env_dir() {
  const char* value = std::getenv(kDataDirVariable);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return fs::path(value);
}

// <exe dir>/../share/kinograph; /proc/self/exe is the running program even when called
// through a symlink or from another working directory.
fs::path program_data_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return (exe.parent_path().parent_path() / "share" / "kinograph").lexically_normal();
}

bool is_dir(const fs::path& p) {
  std::error_code ec;
  return !p.empty() && fs::is_directory(p, ec);
}

// `path` below `root`, or nullopt; both compared with symlinks resolved.
std::optional<fs::path> inside(const fs::path& path, const fs::path& root) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(root, ec);
  if (ec) return std::nullopt;
  const fs::path rel = path.lexically_relative(r);
  if (rel.empty() || *rel.begin() == "..") return std::nullopt;
  return rel;
}

}  // namespace

std::vector<fs::path> data_dirs() {
  std::vector<fs::path> dirs;
  if (const auto env = env_dir(); env && is_dir(*env)) dirs.push_back(*env);
  if (const fs::path exe = program_data_dir(); is_dir(exe)) dirs.push_back(exe);
  return dirs;
}

std::string describe_data_dirs() {
  std::string text = kDataDirVariable;
  const auto env = env_dir();
  if (!env) {
    text += " (not set)";
  } else {
    text += '=';
    text += env->string();
    if (!is_dir(*env)) text += " (not a directory)";
  }
  const fs::path exe = program_data_dir();
  if (!exe.empty()) {
    text += " and ";
    text += exe.string();
    if (!is_dir(exe)) text += " (absent)";
  }
  return text;
}

std::string data_relative_path(const std::string& path) {
  if (path.empty()) return path;
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(path, ec);
  if (ec) return path;
  for (const fs::path& dir : data_dirs()) {
    if (auto rel = inside(p, dir)) return rel->string();
    // The build tree's share/kinograph links robots/ to the sources.
    if (auto rel = inside(p, dir / "robots")) return (fs::path("robots") / *rel).string();
  }
  return p.string();
}

}  // namespace kinograph::planning
