#pragma once
// A strict first pass over URDF text, before urdfdom reads it: refuses xacro input and any
// attribute urdfdom would read as a number but cannot (urdfdom drops such elements silently),
// and records where each link and joint is, so the loader's messages can name the line.
#include <map>
#include <string>
#include <vector>

namespace kinograph::dynamics {

/// Where the elements of one URDF are, by name, and how many geometry elements each link has.
struct UrdfOutline {
  /// One `<link>`: its line and the lines of its `<collision>` and `<visual>` children.
  struct Link {
    int line = 0;
    std::vector<int> collision_lines, visual_lines;
  };
  std::map<std::string, Link> links;
  std::map<std::string, int> joint_lines;  ///< 1-based line of each `<joint>`

  /// " (line N)" for a link or joint named in the outline, empty when unknown.
  std::string link_line(const std::string& link) const;
  std::string joint_line(const std::string& joint) const;
};

/// Deepest element nesting a URDF may have (robot, link, collision, geometry, box is 5): the
/// XML parsers under urdfdom recurse per level, so deeper text is refused before they run.
inline constexpr int kMaxUrdfNesting = 100;

/// Reads the XML of a URDF. `source` names it in messages (a path or "<urdf string>").
/// @throws UrdfError for XML nested deeper than kMaxUrdfNesting or that does not parse (with its
/// line), a xacro file ("expand it with
///   xacro first"), a root that is not `<robot>`, or a numeric attribute that is not a list of the
///   right number of finite numbers (sizes must also be > 0), naming the link or joint, the
///   element path and the line; joints that form a loop or give a link two parents.
UrdfOutline outline_urdf(const std::string& xml, const std::string& source);

}  // namespace kinograph::dynamics
