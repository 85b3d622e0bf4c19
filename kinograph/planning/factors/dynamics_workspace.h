#pragma once
// The dynamics scratch shared by the factors of one planning graph.
#include <memory>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/graph/worker_local.h"

namespace kinograph::planning {

/// One dynamics::Data per worker thread (graph::WorkerLocal), so that the factors sharing it
/// may be evaluated in parallel. Keeps the model alive.
class DynamicsWorkspace final : public graph::WorkerLocal<dynamics::Data> {
 public:
  explicit DynamicsWorkspace(std::shared_ptr<const dynamics::Model> model)
      : WorkerLocal([model = std::move(model)] { return std::make_unique<dynamics::Data>(*model); }) {}
};

}  // namespace kinograph::planning
