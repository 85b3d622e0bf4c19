#pragma once
// Time bounds of one joint moving alone under its limits (a double integrator with bounded
// velocity and acceleration), used to refuse problems no plan can solve before any solve.

namespace kinograph::planning {

/// The least time in which one joint can travel `distance` (signed) and end at rest, starting
/// with velocity v0, never exceeding |q̇| ≤ vmax and |q̈| ≤ amax (either may be +inf): the
/// bang-bang (or bang-coast-bang) profile's time, so no motion within the limits is faster.
/// 0 when nothing needs to move; +inf when vmax is 0 and something does. Requires |v0| ≤ vmax.
double min_time_to_rest(double distance, double v0, double vmax, double amax);

/// The distance a joint moving at v0 travels before it can be at rest under |q̈| ≤ amax.
double stopping_distance(double v0, double amax);

}  // namespace kinograph::planning
