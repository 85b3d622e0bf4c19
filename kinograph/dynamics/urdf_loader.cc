// Model construction from URDF through urdfdom: fixed joints merged into their parent body,
// inertias moved to body frames, geometry and mesh paths resolved.
#include <console_bridge/console.h>
#include <spdlog/spdlog.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>

#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/urdf_file_cache.h"
#include "kinograph/dynamics/urdf_outline.h"

namespace kinograph::dynamics {
namespace {

namespace fs = std::filesystem;

// Captures urdfdom's console_bridge messages so the reason for a parse failure ends up in
// the UrdfError, and its warnings in the log, instead of on stderr.
class CapturingHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      if (!errors.empty()) errors += "; ";
      errors += text;
    } else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      warnings.push_back(text);
    }
  }
  std::string errors;
  std::vector<std::string> warnings;
};

std::mutex& parse_mutex() {
  static std::mutex m;
  return m;
}

Eigen::Isometry3d to_isometry(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  T.translation() << p.position.x, p.position.y, p.position.z;
  return T;
}

// Spatial inertia about a frame's origin of a body with mass m, COM c and inertia Ic about the
// COM, all in that frame: [[Ic − m[c]², m[c]], [−m[c], m·1]] (MR eq. 8.32 moved to the origin).
Matrix6 spatial_inertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& Ic) {
  const Eigen::Matrix3d C = skew(c);
  Matrix6 G;
  G.topLeftCorner<3, 3>() = Ic - m * C * C;
  G.topRightCorner<3, 3>() = m * C;
  G.bottomLeftCorner<3, 3>() = -m * C;
  G.bottomRightCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  return G;
}

class Loader {
 public:
  Loader(std::string source, fs::path base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  Model load(const std::string& xml) {
    outline_ = outline_urdf(xml, source_);
    urdf::ModelInterfaceSharedPtr urdf;
    std::string errors;
    std::vector<std::string> warnings;
    {
      std::lock_guard<std::mutex> lock(parse_mutex());
      CapturingHandler handler;
      console_bridge::useOutputHandler(&handler);
      urdf = urdf::parseURDF(xml);
      console_bridge::restorePreviousOutputHandler();
      errors = handler.errors;
      warnings = handler.warnings;
    }
    for (const std::string& w : warnings) spdlog::warn("{}: urdfdom: {}", source_, w);
    if (!urdf) {
      fail("malformed URDF" + (errors.empty() ? std::string() : " (urdfdom: " + errors + ")"));
    }
    if (!urdf->getRoot()) fail("URDF has no root link");
    urdf_ = urdf;
    model_.name = urdf->getName();
    visit(urdf->getRoot(), -1, Eigen::Isometry3d::Identity(), false);
    check_nothing_dropped();
    spdlog::debug("{}: model '{}' with {} bodies, {} frames", source_, model_.name,
                  model_.bodies.size(), model_.frames.size());
    return std::move(model_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw UrdfError(source_ + ": " + what); }

  // Adds `link` (and recursively its subtree) to body `body` at `placement` in that body.
  // `moving` is true when link is the child of a moving joint, which needs an inertial.
  void visit(const urdf::LinkConstSharedPtr& link, int body, const Eigen::Isometry3d& placement,
             bool moving) {
    model_.frames.push_back({link->name, body, placement});
    if (link->inertial) {
      const urdf::Inertial& in = *link->inertial;
      if (!(in.mass >= 0) || !std::isfinite(in.mass)) {
        fail("link '" + link->name + "'" + outline_.link_line(link->name) +
             " <inertial>: mass must be finite and >= 0");
      }
      if (body < 0) {
        model_.base_mass += in.mass;
      } else {
        const Eigen::Isometry3d T = placement * to_isometry(in.origin);
        Eigen::Matrix3d Ic;
        Ic << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
        model_.bodies[body].inertia +=
            spatial_inertia(in.mass, T.translation(), T.linear() * Ic * T.linear().transpose());
      }
    } else if (moving) {
      fail("link '" + link->name + "'" + outline_.link_line(link->name) + " moves (joint '" +
           model_.bodies[body].joint_name + "') but has no <inertial>");
    }
    for (const auto& c : link->collision_array) {
      if (!c || !c->geometry)
        fail("link '" + link->name + "'" + outline_.link_line(link->name) +
             ": a <collision> without a usable <geometry>");
      add_geometry(*c->geometry, c->origin, link->name, body, placement, nullptr, "collision",
                   model_.collision);
    }
    for (const auto& v : link->visual_array) {
      if (!v || !v->geometry)
        fail("link '" + link->name + "'" + outline_.link_line(link->name) +
             ": a <visual> without a usable <geometry>");
      urdf::MaterialSharedPtr mat = v->material;
      if (!mat && !v->material_name.empty()) mat = urdf_->getMaterial(v->material_name);
      add_geometry(*v->geometry, v->origin, link->name, body, placement, mat.get(), "visual",
                   model_.visual);
    }

    for (const auto& joint : link->child_joints) {
      const urdf::LinkConstSharedPtr child = urdf_->getLink(joint->child_link_name);
      const std::string jname = "joint '" + joint->name + "'" + outline_.joint_line(joint->name);
      if (!child) fail(jname + ": child link not found");
      const Eigen::Isometry3d origin =
          placement * to_isometry(joint->parent_to_joint_origin_transform);
      switch (joint->type) {
        case urdf::Joint::FIXED:
          visit(child, body, origin, false);
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC:
          visit(child, add_body(*joint, body, origin), Eigen::Isometry3d::Identity(), true);
          break;
        case urdf::Joint::FLOATING:
          fail(jname + ": unsupported joint type 'floating'");
        case urdf::Joint::PLANAR:
          fail(jname + ": unsupported joint type 'planar'");
        default:
          fail(jname + ": unsupported joint type");
      }
    }
  }

  int add_body(const urdf::Joint& joint, int parent, const Eigen::Isometry3d& parent_to_joint) {
    Body b;
    b.name = joint.child_link_name;
    b.joint_name = joint.name;
    b.parent = parent;
    b.parent_to_joint = parent_to_joint;
    const std::string jname = "joint '" + joint.name + "'" + outline_.joint_line(joint.name);
    Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
    if (!(axis.norm() > 1e-12) || !axis.allFinite()) {
      fail(jname + " <axis>: axis must be a non-zero vector");
    }
    axis.normalize();
    b.screw_axis.setZero();
    if (joint.type == urdf::Joint::PRISMATIC) {
      b.joint_type = JointType::kPrismatic;
      b.screw_axis.tail<3>() = axis;
    } else {
      b.joint_type = JointType::kRevolute;
      b.screw_axis.head<3>() = axis;
    }
    if (joint.limits) {
      if (joint.type != urdf::Joint::CONTINUOUS) {
        b.limits.lower = joint.limits->lower;
        b.limits.upper = joint.limits->upper;
        if (b.limits.lower > b.limits.upper) {
          fail(jname + " <limit>: lower > upper");
        }
      }
      b.limits.velocity = joint.limits->velocity;
      b.limits.effort = joint.limits->effort;
      if (!(b.limits.velocity >= 0)) fail(jname + " <limit>: velocity must be >= 0");
      if (!(b.limits.effort >= 0)) fail(jname + " <limit>: effort must be >= 0");
      // Many vendor files write effort="0" as a placeholder; URDF cannot say "passive", so a
      // scene declares unactuated joints itself.
      if (b.limits.effort == 0) {
        spdlog::warn(
            "{}: {}: effort=\"0\" read as unknown: no torque limit (an unactuated "
            "joint is declared in the scene's 'unactuated' list)",
            source_, jname);
        b.limits.effort = std::numeric_limits<double>::infinity();
      }
    }
    if (joint.dynamics) b.damping = joint.dynamics->damping;
    model_.bodies.push_back(b);
    return static_cast<int>(model_.bodies.size()) - 1;
  }

  void add_geometry(const urdf::Geometry& g, const urdf::Pose& origin, const std::string& link,
                    int body, const Eigen::Isometry3d& placement, const urdf::Material* mat,
                    const char* kind, std::vector<Geometry>& out) {
    Geometry geo;
    geo.origin = placement * to_isometry(origin);
    geo.body = body;
    geo.link_name = link;
    if (mat) {
      geo.rgba << mat->color.r, mat->color.g, mat->color.b, mat->color.a;
    }
    switch (g.type) {
      case urdf::Geometry::SPHERE:
        geo.shape = Geometry::Shape::kSphere;
        geo.size << static_cast<const urdf::Sphere&>(g).radius, 0, 0;
        break;
      case urdf::Geometry::BOX: {
        const auto& d = static_cast<const urdf::Box&>(g).dim;
        geo.shape = Geometry::Shape::kBox;
        geo.size << d.x, d.y, d.z;
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(g);
        geo.shape = Geometry::Shape::kCylinder;
        geo.size << c.radius, c.length, 0;
        break;
      }
      case urdf::Geometry::MESH: {
        const auto& m = static_cast<const urdf::Mesh&>(g);
        geo.shape = Geometry::Shape::kMesh;
        geo.mesh_path = resolve_mesh(m.filename, link, kind);
        geo.mesh_scale << m.scale.x, m.scale.y, m.scale.z;
        break;
      }
    }
    out.push_back(std::move(geo));
  }

  // package://<pkg>/rest: the nearest folder named <pkg> found walking up from the URDF's
  // folder (the folder itself, or a child of it or of an ancestor); file:// and plain paths
  // are absolute or relative to the URDF's folder.
  std::string resolve_mesh(const std::string& uri, const std::string& link,
                           const char* kind) const {
    const std::string where = "link '" + link + "' <" + kind + "><mesh filename='" + uri + "'>";
    std::vector<fs::path> candidates;
    const std::string kPackage = "package://", kFile = "file://";
    if (uri.rfind(kPackage, 0) == 0) {
      const std::string rest = uri.substr(kPackage.size());
      const size_t slash = rest.find('/');
      if (slash == std::string::npos || slash == 0) fail(where + ": malformed package:// URI");
      const std::string pkg = rest.substr(0, slash), rel = rest.substr(slash + 1);
      for (fs::path d = fs::absolute(base_dir_);; d = d.parent_path()) {
        if (d.filename() == pkg) candidates.push_back(d / rel);
        candidates.push_back(d / pkg / rel);
        if (d == d.parent_path() || d.empty()) break;
      }
      // ROS's own search path, when set.
      if (const char* ros_path = std::getenv("ROS_PACKAGE_PATH")) {
        std::stringstream dirs(ros_path);
        for (std::string dir; std::getline(dirs, dir, ':');) {
          if (!dir.empty()) candidates.push_back(fs::path(dir) / pkg / rel);
        }
      }
      // Last resort: a URDF shipped at the root of its package under another folder name
      // (e.g. Debian dart-doc's wam/wam.urdf naming package://herb_description/meshes/...).
      for (fs::path d = fs::absolute(base_dir_);; d = d.parent_path()) {
        candidates.push_back(d / rel);
        if (d == d.parent_path() || d.empty()) break;
      }
    } else {
      fs::path p = uri.rfind(kFile, 0) == 0 ? fs::path(uri.substr(kFile.size())) : fs::path(uri);
      candidates.push_back(p.is_absolute() ? p : fs::absolute(base_dir_) / p);
    }
    for (const fs::path& c : candidates) {
      std::error_code ec;
      if (fs::is_regular_file(c, ec)) return fs::weakly_canonical(c, ec).string();
    }
    fail(where + ": mesh file not found (first looked for " + candidates.front().string() + ")");
  }

  // urdfdom skips some elements it cannot read without an error; every <collision> and <visual>
  // the text holds must have become a shape.
  void check_nothing_dropped() const {
    for (const auto& entry : outline_.links) {
      // Not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
      const std::string& name = entry.first;
      const UrdfOutline::Link& link = entry.second;
      const urdf::LinkConstSharedPtr l = urdf_->getLink(name);
      if (!l) fail("link '" + name + "'" + outline_.link_line(name) + " was not read by urdfdom");
      const auto check = [&](size_t read, const std::vector<int>& lines, const char* kind) {
        if (read == lines.size()) return;
        fail("link '" + name + "': " + std::to_string(lines.size()) + " <" + kind + "> elements" +
             (lines.empty() ? "" : " (first on line " + std::to_string(lines.front()) + ")") +
             " but urdfdom read " + std::to_string(read) +
             "; one of them has geometry it could not parse");
      };
      check(l->collision_array.size(), link.collision_lines, "collision");
      check(l->visual_array.size(), link.visual_lines, "visual");
    }
  }

  std::string source_;
  fs::path base_dir_;
  UrdfOutline outline_;
  urdf::ModelInterfaceSharedPtr urdf_;
  Model model_;
};

Model load_urdf_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw UrdfError(path + ": URDF file does not exist");
  if (fs::is_directory(path, ec)) throw UrdfError(path + ": is a directory, not a URDF file");
  if (fs::path(path).extension() == ".xacro") {
    throw UrdfError(path + ": this is a xacro file: expand it with xacro first (xacro " + path +
                    " > robot.urdf)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UrdfError(path + ": cannot open URDF file for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw UrdfError(path + ": error while reading URDF file");
  const fs::path abs = fs::absolute(path);
  Model m = Loader(path, abs.parent_path()).load(text.str());
  m.urdf_path = abs.string();
  return m;
}

}  // namespace

Model Model::from_urdf_file(const std::string& path) {
  if (UrdfFileCache* cache = UrdfFileCache::active()) return cache->get(path, &load_urdf_file);
  return load_urdf_file(path);
}

Model Model::from_urdf_string(const std::string& xml, const std::string& base_dir) {
  return Loader("<urdf string>", base_dir.empty() ? fs::current_path() : fs::path(base_dir))
      .load(xml);
}

}  // namespace kinograph::dynamics
