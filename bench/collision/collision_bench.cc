// Collision queries on the iiwa14 against 5 obstacles, per configuration: forward kinematics
// plus every robot-geometry/obstacle pair within the query distance (culled), every pair
// without culling, the closest pair only, and each with the gradient ∂d/∂q of every reported
// pair. Random configurations within the joint limits (seeded). Each configuration is timed
// `repeats` times and keeps its median (the machine is shared, so single runs see
// preemption); the table gives the median, p10 and p90 of those over configurations, in µs
// per configuration. Two cases follow the planners: the desk scene of
// robots/scenes/iiwa_desk.yaml as one world per obstacle (the incremental planner's
// CollisionContexts), and the optimizer's pattern of an error pass then a linearization pass
// (with gradients) over a block of 64 configurations, timed per block (each configuration seen
// once, so no case is helped by a warm cache). Heap allocations inside the timed loops are
// counted too (the queries promise none after warm-up).
//
//   bench_collision [--configs N] [--repeats R]   → JSON on stdout, then a Markdown table
// Replacing the global operator new/delete pair confuses GCC's mismatch analysis of inlined
// std::allocator code; the pair below is consistent (malloc/free).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/distance_gradient.h"
#include "kinograph/dynamics/kinematics.h"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using kinograph::collision::CollisionWorld;
using kinograph::collision::CollisionWorldOptions;
using kinograph::collision::DistanceGradientWorkspace;
using kinograph::collision::Obstacle;
using kinograph::collision::Proximity;
using kinograph::collision::Shape;
namespace dyn = kinograph::dynamics;

Obstacle obstacle(int id, Shape shape, double x, double y, double z, double yaw = 0) {
  Obstacle o;
  o.id = id;
  o.shape = std::move(shape);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  o.pose.translation() = Eigen::Vector3d(x, y, z);
  return o;
}

struct Stats {
  double median, p10, p90;
};

Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  auto at = [&](double f) { return v[static_cast<size_t>(f * (v.size() - 1))]; };
  return {at(0.5), at(0.1), at(0.9)};
}

}  // namespace

int main(int argc, char** argv) {
  int configs = 1000, repeats = 21;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--configs")) configs = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeats")) repeats = std::atoi(argv[i + 1]);
  }
  const dyn::Model model =
      dyn::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf");
  dyn::Data data(model);
  // A desk-like scene around the arm (the paper's task 1 has the arm reach under a desk).
  const std::vector<Obstacle> obstacles = {
      obstacle(0, Shape::box(0.8, 1.2, 0.05), 0.65, 0, 0.55),       // desk top
      obstacle(1, Shape::box(0.05, 0.05, 0.55), 0.3, 0.55, 0.275),  // desk leg
      obstacle(2, Shape::sphere(0.1), -0.4, 0.3, 0.9),
      obstacle(3, Shape::cylinder(0.06, 0.6), -0.3, -0.5, 0.5),
      obstacle(4, Shape::capsule(0.05, 0.5), 0.2, -0.6, 1.0, 0.7)};
  CollisionWorldOptions culled_opts;  // defaults: query distance 0.3 m, culling on
  CollisionWorldOptions all_opts = culled_opts;
  all_opts.cull = false;
  all_opts.query_distance = INFINITY;
  CollisionWorld culled(model, culled_opts), all(model, all_opts);
  for (const Obstacle& o : obstacles) {
    culled.add_obstacle(o);
    all.add_obstacle(o);
  }
  // robots/scenes/iiwa_desk.yaml: tabletop and four legs, one world each.
  const std::vector<Obstacle> desk = {obstacle(0, Shape::box(0.5, 1.0, 0.04), 0.75, 0, 0.64),
                                      obstacle(1, Shape::box(0.04, 0.04, 0.62), 0.52, 0.48, 0.31),
                                      obstacle(2, Shape::box(0.04, 0.04, 0.62), 0.52, -0.48, 0.31),
                                      obstacle(3, Shape::box(0.04, 0.04, 0.62), 0.98, 0.48, 0.31),
                                      obstacle(4, Shape::box(0.04, 0.04, 0.62), 0.98, -0.48, 0.31)};
  std::vector<std::unique_ptr<CollisionWorld>> desk_worlds;
  for (const Obstacle& o : desk) {
    desk_worlds.push_back(std::make_unique<CollisionWorld>(model, culled_opts));
    desk_worlds.back()->add_obstacle(o);
  }
  DistanceGradientWorkspace ws(model);
  Eigen::VectorXd grad(model.nq());

  std::mt19937 rng(2024);
  std::vector<Eigen::VectorXd> qs;
  for (int c = 0; c < configs; ++c) {
    Eigen::VectorXd q(model.nq());
    for (int j = 0; j < model.nq(); ++j) {
      const auto& lim = model.bodies[j].limits;
      q[j] = std::uniform_real_distribution<double>(lim.lower, lim.upper)(rng);
    }
    qs.push_back(q);
  }

  double sink = 0;
  long pairs_total = 0;
  auto query_case = [&](CollisionWorld& world, bool gradients) {
    return [&world, gradients, &data, &model, &ws, &grad, &sink,
            &pairs_total](const Eigen::VectorXd& q) {
      dyn::forward_kinematics(model, data, q);
      for (const Proximity& p : world.query(data)) {
        sink += p.distance;
        ++pairs_total;
        if (gradients) {
          kinograph::collision::distance_gradient(model, data, p, ws, grad);
          sink += grad[0];
        }
      }
    };
  };
  struct Case {
    std::string name;
    std::function<void(const Eigen::VectorXd&)> run;
  };
  const std::vector<Case> cases = {
      {"fk_only", [&](const Eigen::VectorXd& q) { dyn::forward_kinematics(model, data, q); }},
      {"culled_0.3m", query_case(culled, false)},
      {"culled_0.3m_with_gradients", query_case(culled, true)},
      {"all_pairs", query_case(all, false)},
      {"all_pairs_with_gradients", query_case(all, true)},
      {"closest_only",
       [&](const Eigen::VectorXd& q) {
         dyn::forward_kinematics(model, data, q);
         sink += culled.closest(data).distance;
       }},
      {"desk_world_per_obstacle_with_gradients",
       [&](const Eigen::VectorXd& q) {
         dyn::forward_kinematics(model, data, q);
         for (auto& w : desk_worlds) {
           for (const Proximity& p : w->query(data)) {
             kinograph::collision::distance_gradient(model, data, p, ws, grad);
             sink += p.distance + grad[0];
             ++pairs_total;
           }
         }
       }},
  };

  nlohmann::json out;
  out["robot"] = "iiwa14";
  out["robot_geometries"] = model.collision.size();
  out["obstacles"] = obstacles.size();
  out["configs"] = configs;
  out["repeats"] = repeats;
  out["unit"] = "us per configuration (FK included)";
  for (const Case& c : cases) {
    for (const auto& q : qs) c.run(q);  // warm-up
    pairs_total = 0;
    std::vector<double> us(configs), runs(repeats);
    const long alloc_before = g_allocations.load();
    for (int i = 0; i < configs; ++i) {
      for (int r = 0; r < repeats; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        c.run(qs[i]);
        const auto t1 = std::chrono::steady_clock::now();
        runs[r] = std::chrono::duration<double, std::micro>(t1 - t0).count();
      }
      std::nth_element(runs.begin(), runs.begin() + repeats / 2, runs.end());
      us[i] = runs[repeats / 2];
    }
    const long allocations = g_allocations.load() - alloc_before;
    const Stats s = stats(us);
    out["cases"].push_back({{"name", c.name},
                            {"median_us", s.median},
                            {"p10_us", s.p10},
                            {"p90_us", s.p90},
                            {"mean_pairs", double(pairs_total) / (double(configs) * repeats)},
                            {"heap_allocations", allocations}});
  }
  {
    // The optimizer's pattern: an error pass over a block of configurations, then a
    // linearization pass (with gradients) at the same configurations.
    constexpr int kBlock = 64;
    const int blocks = std::max(1, configs / kBlock);
    auto pass = [&](int b, bool gradients) {
      for (int i = b * kBlock; i < std::min(configs, (b + 1) * kBlock); ++i) {
        dyn::forward_kinematics(model, data, qs[i]);
        for (auto& w : desk_worlds) {
          for (const Proximity& p : w->query(data)) {
            sink += p.distance;
            ++pairs_total;
            if (gradients) {
              kinograph::collision::distance_gradient(model, data, p, ws, grad);
              sink += grad[0];
            }
          }
        }
      }
    };
    pass(0, false);  // warm-up (block 0 is not timed)
    pass(0, true);
    pairs_total = 0;
    std::vector<double> us;
    us.reserve(blocks);
    const long alloc_before = g_allocations.load();
    for (int b = 1; b < blocks; ++b) {
      const auto t0 = std::chrono::steady_clock::now();
      pass(b, false);
      pass(b, true);
      const auto t1 = std::chrono::steady_clock::now();
      us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / kBlock);
    }
    const long allocations = g_allocations.load() - alloc_before;
    if (!us.empty()) {
      const Stats s = stats(us);
      out["cases"].push_back({{"name", "desk_error_then_linearize_pass"},
                              {"median_us", s.median},
                              {"p10_us", s.p10},
                              {"p90_us", s.p90},
                              {"mean_pairs", double(pairs_total) / (double(blocks - 1) * kBlock)},
                              {"heap_allocations", allocations}});
    }
  }
  std::printf("%s\n\n", out.dump(2).c_str());
  std::printf("iiwa14 (%zu collision geometries) vs %zu obstacles, %d configurations x %d\n\n",
              model.collision.size(), obstacles.size(), configs, repeats);
  std::printf("| case | median µs | p10 µs | p90 µs | pairs/config | heap allocs |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const auto& c : out["cases"]) {
    std::printf("| %s | %.2f | %.2f | %.2f | %.1f | %ld |\n", c["name"].get<std::string>().c_str(),
                c["median_us"].get<double>(), c["p10_us"].get<double>(), c["p90_us"].get<double>(),
                c["mean_pairs"].get<double>(), c["heap_allocations"].get<long>());
  }
  return sink == 12345.678 ? 1 : 0;  // keeps the work observable
}
