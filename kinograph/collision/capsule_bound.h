#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>

#include "kinograph/collision/convex_shape.h"

namespace kinograph::collision {

// A capsule (points within `radius` of the segment a–b) that contains a solid: a bound tighter
// than a sphere for long links, cheap to test against another capsule, a sphere or a box.
struct CapsuleBound {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0;
};

// A capsule containing the shape, in its own frame: exact for spheres and capsules; a
// cylinder's axis with its radius; a box's longest axis with half the diagonal of the other
// two sides; a mesh's bounding sphere (a zero-length segment).
CapsuleBound capsule_bound(const ConvexShape& shape);

// The capsule in another frame.
CapsuleBound transformed(const Eigen::Isometry3d& pose, const CapsuleBound& c);

// A capsule containing all of `parts` (none: a zero capsule), along the longest part's segment.
CapsuleBound enclosing(std::span<const CapsuleBound> parts);

// Distance between the segments p0–p1 and q0–q1 (closed form, Ericson's Real-Time Collision
// Detection §5.1.9).
double segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& q0, const Eigen::Vector3d& q1);

// Lower bound of the signed distance of any two solids inside x and y, penetration included:
// the segments' distance minus both radii.
double lower_bound(const CapsuleBound& x, const CapsuleBound& y);

// Lower bound of the signed distance of a solid inside x and one inside the sphere about
// `centre` with `radius`.
double lower_bound(const CapsuleBound& x, const Eigen::Vector3d& centre, double radius);

// Lower bound of the signed distance of a solid inside x and one inside the axis-aligned box
// lo–hi, from the gap between the box and the box around x's segment; -inf when those overlap
// (the bound then says nothing of the penetration depth).
double lower_bound(const CapsuleBound& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

}  // namespace kinograph::collision
