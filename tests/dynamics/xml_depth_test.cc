// The nesting depth of XML text as TinyXML would descend into it, found without parsing: what
// counts (start tags not closed by "/>") and what does not (comments, CDATA, declarations,
// quoted attribute values, end tags), and the line of the first element too deep.
#include "kinograph/dynamics/xml_depth.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace kinograph::dynamics {
namespace {

std::string nested(int depth) {
  std::string open, close;
  for (int i = 0; i < depth; ++i) open += "<a x='1'>", close += "</a>";
  return open + close;
}

TEST(XmlDepth, CountsOpenElementsOnly) {
  EXPECT_FALSE(find_nesting_beyond(nested(3), 3).exceeded);
  EXPECT_TRUE(find_nesting_beyond(nested(4), 3).exceeded);
  // Siblings and self-closing elements do not nest.
  EXPECT_FALSE(find_nesting_beyond("<r><a/><a/><a x=\"1\"/><b></b><b></b></r>", 2).exceeded);
  EXPECT_FALSE(find_nesting_beyond("<r><a><b/></a></r>", 2).exceeded);
  EXPECT_TRUE(find_nesting_beyond("<r><a><b></b></a></r>", 2).exceeded);
}

TEST(XmlDepth, SkipsWhatIsNoElement) {
  const std::string hidden = "<?xml version='1.0'?><!DOCTYPE r><r><!-- <a><a><a> -->"
                             "<![CDATA[<a><a><a>]]><a q='<b><c>' p=\"/>\"></a></r>";
  EXPECT_FALSE(find_nesting_beyond(hidden, 2).exceeded);
  EXPECT_TRUE(find_nesting_beyond(hidden, 1).exceeded);
}

TEST(XmlDepth, NamesTheLineOfTheFirstElementTooDeep) {
  const XmlDepth d = find_nesting_beyond("<r>\n<a>\n\n<b>\n<c/></b></a></r>", 2);
  EXPECT_TRUE(d.exceeded);
  EXPECT_EQ(d.line, 4);
}

TEST(XmlDepth, TheShippedRobotsAreShallow) {
  for (const char* robot : {"iiwa14/iiwa14.urdf", "rr/rr.urdf", "acrobot/acrobot.urdf"}) {
    std::ifstream in(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/" + robot);
    std::stringstream text;
    text << in.rdbuf();
    ASSERT_FALSE(text.str().empty()) << robot;
    EXPECT_FALSE(find_nesting_beyond(text.str(), 6).exceeded) << robot;
  }
}

}  // namespace
}  // namespace kinograph::dynamics
