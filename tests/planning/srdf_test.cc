// The SRDF allowed-collision reader: the shipped iiwa file, links merged by fixed joints, and
// every kind of bad input naming the file, the line and the element.
#include "kinograph/planning/io/srdf.h"

#include <gtest/gtest.h>

#include <string>

#include "kinograph/dynamics/model.h"

namespace kinograph::planning {
namespace {

const std::string kIiwa = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/";

dynamics::Model iiwa() { return dynamics::Model::from_urdf_file(kIiwa + "iiwa14.urdf"); }

// The message of the SrdfError that `f` throws, with its line.
template <typename F>
std::pair<std::string, int> error_of(F&& f) {
  try {
    f();
  } catch (const SrdfError& e) {
    return {e.what(), e.line()};
  }
  ADD_FAILURE() << "no SrdfError";
  return {"", -1};
}

TEST(Srdf, ShippedIiwaFileAllowsTheWristPair) {
  const std::vector<DisabledCollision> list = load_srdf(kIiwa + "iiwa14.srdf");
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].link1, "iiwa_link_5");
  EXPECT_EQ(list[0].link2, "iiwa_link_7");
  EXPECT_EQ(list[0].reason, "User");
  EXPECT_EQ(list[0].line, 7);
  const auto pairs = allowed_body_pairs(iiwa(), list, "iiwa14.srdf");
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(4, 6));  // robots/README.md: bodies 4 and 6
}

TEST(Srdf, MergedLinksStandForTheirBodyAndTheBaseIsMinusOne) {
  const std::string xml = R"(<?xml version="1.0"?>
<robot name="iiwa14">
  <group name="arm"><chain base_link="iiwa_link_0" tip_link="iiwa_link_ee"/></group>
  <disable_collisions link1="iiwa_link_0" link2="iiwa_link_ee" reason="Never"/>
  <disable_collisions link2="iiwa_link_3" link1="iiwa_link_1"/>
</robot>)";
  const std::vector<DisabledCollision> list = parse_srdf(xml, "t.srdf");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1].line, 5);
  EXPECT_EQ(list[1].reason, "");
  const auto pairs = allowed_body_pairs(iiwa(), list, "t.srdf");
  EXPECT_EQ(pairs[0], std::make_pair(-1, 6));  // iiwa_link_ee is fixed to link 7 (body 6)
  EXPECT_EQ(pairs[1], std::make_pair(0, 2));
}

TEST(Srdf, MalformedXmlNamesTheFileAndLine) {
  const std::string xml =
      "<robot name=\"r\">\n  <disable_collisions link1=\"a\" link2=\"b\"/>\n"
      "  <disable_collisions link1=\"a\" link2=\"b\">\n</robot>\n";
  const auto [what, line] = error_of([&] { parse_srdf(xml, "bad.srdf"); });
  EXPECT_EQ(line, 4);
  EXPECT_NE(what.find("bad.srdf"), std::string::npos) << what;
  EXPECT_NE(what.find("line 4"), std::string::npos) << what;
  EXPECT_NE(what.find("not well-formed"), std::string::npos) << what;
}

TEST(Srdf, MissingLinkAttributeNamesTheElement) {
  const std::string xml =
      "<robot name=\"r\">\n\n  <disable_collisions link1=\"a\" reason=\"x\"/>\n"
      "</robot>\n";
  const auto [what, line] = error_of([&] { parse_srdf(xml, "m.srdf"); });
  EXPECT_EQ(line, 3);
  EXPECT_NE(what.find("<disable_collisions>"), std::string::npos) << what;
  EXPECT_NE(what.find("link2"), std::string::npos) << what;
}

TEST(Srdf, WrongRootIsRefused) {
  const auto [what, line] = error_of([&] { parse_srdf("<sdf>\n</sdf>", "r.srdf"); });
  EXPECT_EQ(line, 1);
  EXPECT_NE(what.find("<sdf>"), std::string::npos) << what;
}

TEST(Srdf, UnknownLinkNamesTheLinkAndLine) {
  const std::string xml =
      "<robot name=\"iiwa14\">\n"
      "  <disable_collisions link1=\"iiwa_link_5\" link2=\"iiwa_link_9\"/>\n"
      "</robot>\n";
  const std::vector<DisabledCollision> list = parse_srdf(xml, "u.srdf");
  const auto [what, line] = error_of([&] { allowed_body_pairs(iiwa(), list, "u.srdf"); });
  EXPECT_EQ(line, 2);
  EXPECT_NE(what.find("u.srdf"), std::string::npos) << what;
  EXPECT_NE(what.find("'iiwa_link_9'"), std::string::npos) << what;
}

TEST(Srdf, UnreadableFile) {
  const auto [what, line] = error_of([&] { load_srdf("/nonexistent/x.srdf"); });
  EXPECT_EQ(line, 0);
  EXPECT_NE(what.find("cannot open"), std::string::npos) << what;
}

}  // namespace
}  // namespace kinograph::planning
