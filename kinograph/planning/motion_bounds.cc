#include "kinograph/planning/motion_bounds.h"

#include <cmath>
#include <limits>

namespace kinograph::planning {
namespace {

// A duration no motion within the limits reaches.
constexpr double kNever = std::numeric_limits<double>::infinity();

// Rest to rest over distance L ≥ 0: accelerate, coast at vmax if it is reached, decelerate.
double rest_to_rest(double L, double vmax, double amax) {
  if (L <= 0) return 0;
  if (vmax <= 0) return kNever;
  if (std::isinf(amax)) return L / vmax;
  if (L <= vmax * vmax / amax) return 2 * std::sqrt(L / amax);  // triangle: peak below vmax
  return L / vmax + vmax / amax;
}

}  // namespace

double stopping_distance(double v0, double amax) {
  return std::isinf(amax) ? 0.0 : v0 * v0 / (2 * amax);
}

double min_time_to_rest(double distance, double v0, double vmax, double amax) {
  // Work in the direction of travel: d ≥ 0, u0 the start velocity along it.
  const double d = std::abs(distance);
  const double u0 = distance < 0 ? -v0 : v0;
  if (std::isinf(amax)) return d == 0 ? 0.0 : (vmax <= 0 ? kNever : d / vmax);
  if (u0 < 0) {
    // Moving away: stop first (the shortest way to rest), then go from rest.
    return -u0 / amax + rest_to_rest(d + stopping_distance(u0, amax), vmax, amax);
  }
  const double s_stop = stopping_distance(u0, amax);
  if (s_stop > d) {
    // Too fast to stop in time: brake fully, overshoot, come back from rest.
    return u0 / amax + rest_to_rest(s_stop - d, vmax, amax);
  }
  // Accelerate from u0 to a peak vp, then brake to rest: (vp² − u0²)/2a + vp²/2a = d.
  const double vp = std::sqrt(amax * d + 0.5 * u0 * u0);
  if (vp <= vmax) return (2 * vp - u0) / amax;
  const double accelerating = (vmax * vmax - u0 * u0) / (2 * amax);
  const double braking = vmax * vmax / (2 * amax);
  return (vmax - u0) / amax + vmax / amax + (d - accelerating - braking) / vmax;
}

}  // namespace kinograph::planning
