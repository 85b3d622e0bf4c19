#include "kinograph/dynamics/urdf_file_cache.h"

#include <atomic>
#include <stdexcept>

namespace kinograph::dynamics {
namespace {

std::atomic<UrdfFileCache*> g_active{nullptr};

}  // namespace

UrdfFileCache::UrdfFileCache() {
  UrdfFileCache* expected = nullptr;
  if (!g_active.compare_exchange_strong(expected, this)) {
    throw std::logic_error("UrdfFileCache: one is already in scope");
  }
}

UrdfFileCache::~UrdfFileCache() { g_active.store(nullptr); }

int UrdfFileCache::loads() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(entries_.size());
}

UrdfFileCache* UrdfFileCache::active() { return g_active.load(); }

Model UrdfFileCache::get(const std::string& path, Model (*load)(const std::string&)) {
  const std::lock_guard<std::mutex> lock(mutex_);
  auto it = entries_.find(path);
  if (it == entries_.end()) {
    std::variant<Model, std::exception_ptr> entry;
    try {
      entry = load(path);
    } catch (...) {
      entry = std::current_exception();
    }
    it = entries_.emplace(path, std::move(entry)).first;
  }
  if (const auto* error = std::get_if<std::exception_ptr>(&it->second)) {
    std::rethrow_exception(*error);
  }
  return std::get<Model>(it->second);
}

}  // namespace kinograph::dynamics
