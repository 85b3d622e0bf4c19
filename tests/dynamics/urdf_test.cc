// URDF loading: tree flattening, fixed-joint merging, limits, geometry and mesh paths, and
// every bad-input case (each must throw UrdfError naming the file and the element, silently).
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/model.h"
#include "test_util.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::dynamics {
namespace {

namespace fs = std::filesystem;

// Expects UrdfError from loading `path`, with every `needle` in its message and no output on
// stderr (urdfdom's console_bridge messages are captured, not printed).
void expect_urdf_error(const std::string& path, std::initializer_list<std::string> needles) {
  ::testing::internal::CaptureStderr();
  try {
    Model::from_urdf_file(path);
    ADD_FAILURE() << "no UrdfError for " << path;
  } catch (const UrdfError& e) {
    const std::string msg = e.what();
    for (const std::string& n : needles) {
      EXPECT_NE(msg.find(n), std::string::npos) << "'" << n << "' not in: " << msg;
    }
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

// The log lines (warnings and above) written while `load` runs.
template <typename F>
std::vector<std::string> warnings_of(F&& load) {
  auto sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(64);
  auto previous = spdlog::default_logger();
  auto logger = std::make_shared<spdlog::logger>("capture", sink);
  logger->set_level(spdlog::level::warn);
  spdlog::set_default_logger(logger);
  load();
  spdlog::set_default_logger(previous);
  return sink->last_formatted();
}

bool any_has(const std::vector<std::string>& lines, std::initializer_list<std::string> needles) {
  for (const std::string& l : lines) {
    bool all = true;
    for (const std::string& n : needles) all = all && l.find(n) != std::string::npos;
    if (all) return true;
  }
  return false;
}

// urdfdom alone drops the link's geometry for length="abc" and loads without error.
TEST(UrdfBadInput, UnparsableNumberNamesLinkElementAndLine) {
  expect_urdf_error(testing::data_path("bad_number.urdf"),
                    {"bad_number.urdf", "line 13", "link 'arm'", "<collision><geometry>",
                     "<cylinder length='abc'>", "not a number"});
}

TEST(UrdfBadInput, NonFiniteRadiusIsRefused) {
  // A NaN or infinite collision radius would read as an infinite clearance and hide contact.
  for (const char* v : {"nan", "inf"}) {
    const std::string file = std::string(v) + "_radius.urdf";
    expect_urdf_error(testing::data_path(file),
                      {file, "line 13", "link 'arm'", "<collision><geometry>",
                       "<sphere radius='" + std::string(v) + "'>", "not a number"});
  }
}

TEST(UrdfBadInput, WrongNumberOfValues) {
  expect_urdf_error(testing::data_path("wrong_count.urdf"),
                    {"wrong_count.urdf", "line 7", "joint 'j1'", "<origin xyz='0 0.2'>",
                     "needs 3 numbers, has 2"});
}

TEST(UrdfBadInput, GeometryUrdfdomCannotReadIsAnError) {
  ::testing::internal::CaptureStderr();
  try {
    Model::from_urdf_file(testing::data_path("unknown_geometry.urdf"));
    ADD_FAILURE() << "no UrdfError";
  } catch (const UrdfError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unknown_geometry.urdf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("arm"), std::string::npos) << msg;
  }
  ::testing::internal::GetCapturedStderr();
}

TEST(UrdfBadInput, NonPositiveSize) {
  const std::string xml = R"(<robot name="r"><link name="base">
    <collision><geometry><sphere radius="-0.1"/></geometry></collision></link></robot>)";
  try {
    Model::from_urdf_string(xml);
    ADD_FAILURE() << "no UrdfError";
  } catch (const UrdfError& e) {
    EXPECT_NE(std::string(e.what()).find("link 'base' <collision><geometry><sphere radius='-0.1'>: "
                                         "must be > 0"),
              std::string::npos)
        << e.what();
  }
}

TEST(UrdfBadInput, XacroRefusedByNameAndByContent) {
  expect_urdf_error(testing::data_path("arm.urdf.xacro"),
                    {"arm.urdf.xacro", "expand it with xacro first"});
  expect_urdf_error(
      testing::data_path("xacro_content.urdf"),
      {"xacro_content.urdf", "line 4", "<xacro:property>", "expand it with xacro first"});
  // A substitution left in an attribute, without any xacro element.
  try {
    Model::from_urdf_string(R"(<robot name="r"><link name="base">
      <visual><geometry><sphere radius="${r}"/></geometry></visual></link></robot>)");
    ADD_FAILURE() << "no UrdfError";
  } catch (const UrdfError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2: <sphere radius='${r}'>: this is a xacro file"),
              std::string::npos)
        << e.what();
  }
  // xacro's output keeps the namespace declaration; expanded, the file loads.
  EXPECT_NO_THROW(Model::from_urdf_string(
      R"(<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="base"/></robot>)"));
}

// effort="0" is a placeholder in many vendor files: unknown, not unactuated; one warning per
// joint, naming it and its line.
TEST(UrdfLoad, ZeroEffortIsUnknownWithAWarning) {
  Model m;
  const auto lines =
      warnings_of([&] { m = Model::from_urdf_file(testing::data_path("zero_effort.urdf")); });
  ASSERT_EQ(m.nq(), 2);
  for (const Body& b : m.bodies) {
    EXPECT_TRUE(b.actuated) << b.joint_name;
    EXPECT_TRUE(std::isinf(b.limits.effort) && b.limits.effort > 0) << b.joint_name;
  }
  EXPECT_TRUE(
      any_has(lines, {"zero_effort.urdf", "joint 'j1' (line 5)", "effort=\"0\"", "unknown"}));
  EXPECT_TRUE(any_has(lines, {"joint 'j2' (line 13)", "unknown"}));
  // A file with real limits loads without a warning.
  EXPECT_TRUE(
      warnings_of([] { Model::from_urdf_file(testing::robot_path("rr/rr.urdf")); }).empty());
}

TEST(UrdfBadInput, MissingFile) {
  expect_urdf_error(testing::data_path("no_such_robot.urdf"),
                    {"no_such_robot.urdf", "does not exist"});
}

TEST(UrdfBadInput, DirectoryInsteadOfFile) {
  expect_urdf_error(testing::data_path("meshpkg"), {"meshpkg", "directory"});
}

TEST(UrdfBadInput, UnreadableFile) {
  if (geteuid() == 0) GTEST_SKIP() << "root can read files without read permission";
  const kinograph::test_support::TempDir dir("kinograph_unreadable");
  const fs::path p = dir / "kinograph_unreadable.urdf";
  std::ofstream(p) << "<robot name='x'/>";
  fs::permissions(p, fs::perms::none);
  expect_urdf_error(p.string(), {"kinograph_unreadable.urdf", "cannot open"});
  fs::remove(p);
}

TEST(UrdfBadInput, MalformedXml) {
  expect_urdf_error(testing::data_path("malformed.urdf"), {"malformed.urdf", "malformed URDF"});
}

// 50,000 nested elements overflowed the stack of the recursive XML parser under urdfdom; deep
// text is refused before it runs, naming the line of the first element too deep.
TEST(UrdfBadInput, DeepNestingIsRefusedWithItsLine) {
  std::string open, close;
  for (int i = 0; i < 50000; ++i) open += "<a>", close += "</a>";
  const std::string xml =
      "<robot name='deep'>\n<link name='base'>\n" + open + close + "</link></robot>";
  try {
    Model::from_urdf_string(xml);
    ADD_FAILURE() << "no UrdfError";
  } catch (const UrdfError& e) {
    EXPECT_NE(std::string(e.what()).find("<urdf string> line 3: elements nested deeper than 100"),
              std::string::npos)
        << e.what();
  }
}

// A text ending inside a multi-byte character made TinyXML read past its end (found by the
// fuzzer, ASan: heap-buffer-overflow in TiXmlBase::ReadName); text that is not UTF-8 is refused
// before TinyXML sees it, naming the line and the byte.
TEST(UrdfBadInput, TextThatIsNotUtf8IsRefusedWithItsLine) {
  for (const std::string tail : {"\xda", "\xc3\x28/>", "\xed\xa0\x80/>", "\xc0\xaf/>"}) {
    const std::string xml = "<robot name='r'>\n<link name='base'/>\n<link name='b" + tail;
    try {
      Model::from_urdf_string(xml);
      ADD_FAILURE() << "no UrdfError";
    } catch (const UrdfError& e) {
      EXPECT_NE(std::string(e.what()).find("<urdf string> line 3: not UTF-8 text: byte 0x"),
                std::string::npos)
          << e.what();
    }
  }
  // Names in other scripts are fine.
  EXPECT_NO_THROW(Model::from_urdf_string("<robot name='Roboter ü 机器人'><link name='base'/></robot>"));
}

// Joints that close a loop (which urdfdom turns into a cycle of shared pointers it never frees,
// found by the fuzzer) or give a link two parents are refused, naming the joint and its line.
TEST(UrdfBadInput, JointsMustFormATree) {
  const auto error_of = [](const std::string& joints) {
    const std::string xml =
        "<robot name='loop'><link name='a'/><link name='b'/><link name='c'/>\n" + joints +
        "</robot>";
    try {
      Model::from_urdf_string(xml);
    } catch (const UrdfError& e) {
      return std::string(e.what());
    }
    return std::string("no UrdfError");
  };
  const auto joint = [](const char* name, const char* parent, const char* child) {
    return std::string("<joint name='") + name + "' type='fixed'><parent link='" + parent +
           "'/><child link='" + child + "'/></joint>\n";
  };
  const std::string loop =
      error_of(joint("ab", "a", "b") + joint("bc", "b", "c") + joint("ca", "c", "a"));
  EXPECT_NE(loop.find("closes a loop"), std::string::npos) << loop;
  EXPECT_NE(loop.find("<urdf string> line "), std::string::npos) << loop;
  const std::string two = error_of(joint("ab", "a", "b") + joint("cb", "c", "b"));
  EXPECT_NE(two.find("line 3: link 'b' is the child of joint 'ab' (line 2) and of joint 'cb'"),
            std::string::npos)
      << two;
}

TEST(UrdfBadInput, FloatingJoint) {
  expect_urdf_error(testing::data_path("floating_joint.urdf"),
                    {"floating_joint.urdf", "floating_base_joint", "floating"});
}

TEST(UrdfBadInput, PlanarJoint) {
  expect_urdf_error(testing::data_path("planar_joint.urdf"),
                    {"planar_joint.urdf", "planar_base_joint", "planar"});
}

TEST(UrdfBadInput, MissingInertialOnMovingLink) {
  expect_urdf_error(testing::data_path("missing_inertial.urdf"),
                    {"missing_inertial.urdf", "massless_arm", "inertial"});
}

TEST(UrdfBadInput, MeshNotFound) {
  expect_urdf_error(testing::data_path("missing_mesh.urdf"),
                    {"missing_mesh.urdf", "l1", "does_not_exist.stl", "not found"});
}

TEST(UrdfBadInput, StringsAndEdgeCases) {
  EXPECT_THROW(Model::from_urdf_string(""), UrdfError);
  EXPECT_THROW(Model::from_urdf_string("<robot name='x'><link name='a'/>"), UrdfError);
  EXPECT_THROW(Model::from_urdf_string("not xml at all"), UrdfError);
  // A zero joint axis cannot define a screw.
  const std::string zero_axis = R"(<robot name="z"><link name="b"/>
    <joint name="jz" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    <link name="c"><inertial><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>)";
  try {
    Model::from_urdf_string(zero_axis);
    ADD_FAILURE();
  } catch (const UrdfError& e) {
    EXPECT_NE(std::string(e.what()).find("jz"), std::string::npos) << e.what();
  }
}

TEST(UrdfLoad, MeshesMaterialsAndMerging) {
  const std::string path = testing::data_path("meshpkg/urdf/meshes.urdf");
  const Model m = Model::from_urdf_file(path);
  const std::string mesh = fs::weakly_canonical(testing::data_path("meshpkg/meshes/wedge.stl"));
  EXPECT_EQ(m.name, "meshes");
  EXPECT_EQ(m.urdf_path, fs::absolute(path).string());
  ASSERT_EQ(m.nq(), 2);

  // Visuals: base (package://, scaled, named material), l1 (relative path, inline material).
  ASSERT_EQ(m.visual.size(), 2u);
  EXPECT_EQ(m.visual[0].shape, Geometry::Shape::kMesh);
  EXPECT_EQ(m.visual[0].mesh_path, mesh);
  EXPECT_EQ(m.visual[0].body, -1);
  EXPECT_TRUE(m.visual[0].mesh_scale.isApprox(Eigen::Vector3d(2, 2, 2)));
  EXPECT_TRUE(m.visual[0].rgba.isApprox(Eigen::Vector4d(0, 0.5, 0.5, 1)));
  EXPECT_EQ(m.visual[1].mesh_path, mesh);
  EXPECT_EQ(m.visual[1].body, 0);
  EXPECT_TRUE(m.visual[1].rgba.isApprox(Eigen::Vector4d(1, 0, 0, 1)));

  // Collisions: l1's mesh and box, then the merged tool link's sphere and cylinder, posed in
  // body l1 through the fixed joint (z 0.3, yaw π/2).
  ASSERT_EQ(m.collision.size(), 4u);
  EXPECT_EQ(m.collision[0].shape, Geometry::Shape::kMesh);
  EXPECT_EQ(m.collision[1].shape, Geometry::Shape::kBox);
  EXPECT_TRUE(m.collision[1].size.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_EQ(m.collision[2].shape, Geometry::Shape::kSphere);
  EXPECT_DOUBLE_EQ(m.collision[2].size.x(), 0.04);
  EXPECT_EQ(m.collision[2].body, 0);
  EXPECT_EQ(m.collision[2].link_name, "tool_link");
  EXPECT_TRUE(m.collision[2].origin.translation().isApprox(Eigen::Vector3d(0, 0, 0.35)));
  EXPECT_EQ(m.collision[3].shape, Geometry::Shape::kCylinder);
  EXPECT_TRUE(m.collision[3].size.isApprox(Eigen::Vector3d(0.02, 0.1, 0)));

  // Continuous joint: unbounded, axis normalised; default grey where no material.
  const Body& b0 = m.bodies[0];
  EXPECT_TRUE(std::isinf(b0.limits.lower) && b0.limits.lower < 0);
  EXPECT_TRUE(std::isinf(b0.limits.upper));
  EXPECT_TRUE(std::isinf(b0.limits.effort));
  EXPECT_TRUE(b0.actuated);
  EXPECT_TRUE(b0.screw_axis.isApprox((Vector6() << 0, 0, 1, 0, 0, 0).finished()));
  // Merged inertia: 1 kg at the origin plus 0.5 kg at (0, 0.1, 0.3) (yawed fixed joint).
  EXPECT_NEAR(b0.inertia(3, 3), 1.5, 1e-12);
  const Eigen::Matrix3d mc = b0.inertia.topRightCorner<3, 3>();
  EXPECT_TRUE(Eigen::Vector3d(mc(2, 1), mc(0, 2), mc(1, 0))
                  .isApprox(0.5 * Eigen::Vector3d(0, 0.1, 0.3), 1e-12));

  // Prismatic child of the merged link: placement through the fixed joint, effort 0 (unknown).
  const Body& b1 = m.bodies[1];
  EXPECT_EQ(b1.joint_type, JointType::kPrismatic);
  EXPECT_EQ(b1.parent, 0);
  EXPECT_TRUE(b1.actuated);
  EXPECT_TRUE(std::isinf(b1.limits.effort));
  EXPECT_DOUBLE_EQ(b1.damping, 3.0);
  EXPECT_DOUBLE_EQ(b1.limits.upper, 0.04);
  EXPECT_TRUE(b1.parent_to_joint.translation().isApprox(Eigen::Vector3d(0, 0, 0.3)));
  EXPECT_TRUE(b1.screw_axis.isApprox((Vector6() << 0, 0, 0, 0, 1, 0).finished()));

  // Frames: every link, merged ones on their body.
  const Frame& tool = m.frames[m.frame_index("tool_link")];
  EXPECT_EQ(tool.body, 0);
  EXPECT_EQ(m.frames[m.frame_index("base")].body, -1);
  Data d(m);
  forward_kinematics(m, d, Eigen::Vector2d(M_PI / 2, 0.02));
  // At q1 = π/2 the tool frame is yawed by π; the finger slides along its own y, i.e. −y.
  EXPECT_TRUE(d.body_pose[1].translation().isApprox(Eigen::Vector3d(0, -0.02, 0.8), 1e-12))
      << d.body_pose[1].translation().transpose();
}

TEST(UrdfLoad, ShippedRobotsLoad) {
  for (const char* r : {"acrobot/acrobot.urdf", "rr/rr.urdf", "iiwa14/iiwa14.urdf"}) {
    ::testing::internal::CaptureStderr();
    EXPECT_NO_THROW(Model::from_urdf_file(testing::robot_path(r))) << r;
    ::testing::internal::GetCapturedStderr();
  }
  const Model rr = Model::from_urdf_file(testing::robot_path("rr/rr.urdf"));
  ASSERT_EQ(rr.nq(), 2);
  EXPECT_NEAR(rr.total_mass(), 3.5, 1e-12);
  EXPECT_TRUE(rr.bodies[0].actuated && rr.bodies[1].actuated);
}

TEST(UrdfLoad, TreeIsTopologicallyOrdered) {
  const Model m = Model::from_urdf_string(testing::kTreeUrdf);
  ASSERT_EQ(m.nq(), 6);
  for (int i = 0; i < m.nq(); ++i) EXPECT_LT(m.bodies[i].parent, i);
  EXPECT_EQ(m.bodies[m.body_index("d")].parent, m.body_index("c"));
  EXPECT_EQ(m.bodies[m.body_index("f")].parent, m.body_index("e"));
  EXPECT_EQ(m.frames[m.frame_index("c_ext")].body, m.body_index("c"));
  EXPECT_EQ(m.frames[m.frame_index("e_tool_frame")].body, m.body_index("e"));
}

}  // namespace
}  // namespace kinograph::dynamics
