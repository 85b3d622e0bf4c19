// The Data workspace makes every algorithm allocation-free: count heap allocations through a
// replaced global operator new while the algorithms run.
// The replacements pair malloc with free; GCC cannot see that and warns on the delete.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/model.h"
#include "test_util.h"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace kinograph::dynamics {
namespace {

TEST(Allocation, AlgorithmsAllocateNothing) {
  for (const Model& model : {Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf")),
                             Model::from_urdf_string(testing::kTreeUrdf)}) {
    const int n = model.nq();
    Data data(model);
    std::mt19937 rng(31);
    const Eigen::VectorXd q = testing::random_vector(rng, n, 2.0);
    const Eigen::VectorXd qd = testing::random_vector(rng, n, 2.0);
    const Eigen::VectorXd qdd = testing::random_vector(rng, n, 2.0);
    const std::vector<ExternalWrench> ext = {{n - 1, Vector6::Ones()}};
    Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, n);
    Eigen::Matrix3Xd Jp(3, n);
    const Eigen::Vector3d p(0.1, 0.2, 0.3);
    const std::vector<int> passive = {0, n - 1};
    passive_dynamics(model, data, q, qd, qdd, passive, true, ext);  // sizes its workspace
    const long before = g_allocations.load();
    for (int k = 0; k < 3; ++k) {
      forward_kinematics(model, data, q);
      space_jacobian(model, data, n - 1, J);
      point_jacobian(model, data, n - 1, p, Jp);
      rnea(model, data, q, qd, qdd, ext);
      rnea_derivatives(model, data, q, qd, qdd, ext);
      mass_matrix(model, data, q);
      forward_dynamics(model, data, q, qd, data.tau, ext);
      passive_dynamics(model, data, q, qd, qdd, passive, k % 2 == 0, ext);
    }
    EXPECT_EQ(g_allocations.load() - before, 0);
    // Sanity: the counter does see allocations.
    const long probe = g_allocations.load();
    std::vector<double>* v = new std::vector<double>(10);
    delete v;
    EXPECT_GT(g_allocations.load(), probe);
  }
}

}  // namespace
}  // namespace kinograph::dynamics
