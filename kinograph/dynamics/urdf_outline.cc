#include "kinograph/dynamics/urdf_outline.h"

#include <tinyxml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "kinograph/dynamics/urdf_error.h"
#include "kinograph/dynamics/utf8.h"
#include "kinograph/dynamics/xml_depth.h"

namespace kinograph::dynamics {
namespace {

// A numeric attribute as urdfdom reads it: `count` numbers, all > 0 when `positive`.
struct NumericAttribute {
  const char* element;
  const char* attribute;
  int count;
  bool positive;
};

// The URDF attributes urdfdom parses as numbers (urdfdom 3 / URDF spec).
constexpr NumericAttribute kNumeric[] = {
    {"origin", "xyz", 3, false},
    {"origin", "rpy", 3, false},
    {"axis", "xyz", 3, false},
    {"limit", "lower", 1, false},
    {"limit", "upper", 1, false},
    {"limit", "effort", 1, false},
    {"limit", "velocity", 1, false},
    {"dynamics", "damping", 1, false},
    {"dynamics", "friction", 1, false},
    {"mass", "value", 1, false},
    {"inertia", "ixx", 1, false},
    {"inertia", "ixy", 1, false},
    {"inertia", "ixz", 1, false},
    {"inertia", "iyy", 1, false},
    {"inertia", "iyz", 1, false},
    {"inertia", "izz", 1, false},
    {"box", "size", 3, true},
    {"cylinder", "radius", 1, true},
    {"cylinder", "length", 1, true},
    {"sphere", "radius", 1, true},
    {"mesh", "scale", 3, false},
    {"color", "rgba", 4, false},
    {"mimic", "multiplier", 1, false},
    {"mimic", "offset", 1, false},
    {"calibration", "rising", 1, false},
    {"calibration", "falling", 1, false},
    {"safety_controller", "soft_lower_limit", 1, false},
    {"safety_controller", "soft_upper_limit", 1, false},
    {"safety_controller", "k_position", 1, false},
    {"safety_controller", "k_velocity", 1, false},
};

// Whitespace-separated finite numbers; false when any token is not one.
bool parse_numbers(const char* text, std::vector<double>& out) {
  out.clear();
  std::istringstream in(text);
  for (std::string token; in >> token;) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) return false;
    out.push_back(v);
  }
  return true;
}

class Outliner {
 public:
  explicit Outliner(std::string source) : source_(std::move(source)) {}

  UrdfOutline run(const std::string& xml) {
    if (const auto bad = first_invalid_utf8(xml)) {
      char byte[8];
      std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(xml[*bad]));
      fail(line_at(xml, *bad), std::string("not UTF-8 text: byte ") + byte + " at offset " +
                                   std::to_string(*bad));
    }
    if (const XmlDepth deep = find_nesting_beyond(xml, kMaxUrdfNesting); deep.exceeded) {
      fail(deep.line, "elements nested deeper than " + std::to_string(kMaxUrdfNesting) +
                          " levels; a URDF needs a handful");
    }
    TiXmlDocument doc;
    doc.Parse(xml.c_str());
    if (doc.Error()) {
      const bool xacro = xml.find("xmlns:xacro") != std::string::npos;
      fail(doc.ErrorRow(), xacro ? "not valid XML (" + std::string(doc.ErrorDesc()) +
                                       "); it looks like xacro: expand it with xacro first"
                                 : "malformed URDF: " + std::string(doc.ErrorDesc()));
    }
    const TiXmlElement* root = doc.RootElement();
    if (root == nullptr) fail(0, "malformed URDF: no root element");
    check_not_xacro(root);
    if (std::strcmp(root->Value(), "robot") != 0) {
      fail(root->Row(), "root element is <" + std::string(root->Value()) + ">, not <robot>");
    }
    for (const TiXmlElement* e = root->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const std::string kind = e->Value();
      const char* name = e->Attribute("name");
      const std::string label = kind + " '" + (name ? name : "") + "'";
      if (kind == "link") {
        UrdfOutline::Link& link = outline_.links[name ? name : ""];
        link.line = e->Row();
        for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
          if (std::strcmp(c->Value(), "collision") == 0) link.collision_lines.push_back(c->Row());
          if (std::strcmp(c->Value(), "visual") == 0) link.visual_lines.push_back(c->Row());
        }
      } else if (kind == "joint") {
        outline_.joint_lines[name ? name : ""] = e->Row();
        record_edge(e, name ? name : "");
      } else if (kind != "material") {
        continue;  // gazebo, transmission, ...: not read by urdfdom's model parser
      }
      for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
        check_numbers(c, label, "");
      }
    }
    check_tree();
    return std::move(outline_);
  }

 private:
  // One joint as a parent → child edge of the link graph.
  struct Edge {
    std::string joint, parent;
    int line = 0;
  };

  void record_edge(const TiXmlElement* joint, const std::string& name) {
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    const char* p = parent ? parent->Attribute("link") : nullptr;
    const char* c = child ? child->Attribute("link") : nullptr;
    if (p == nullptr || c == nullptr) return;  // urdfdom names what is missing
    const auto [it, added] = parent_of_.emplace(c, Edge{name, p, joint->Row()});
    if (!added) {
      fail(joint->Row(), "link '" + std::string(c) + "' is the child of joint '" +
                             it->second.joint + "' (line " + std::to_string(it->second.line) +
                             ") and of joint '" + name + "' (a URDF is a tree)");
    }
  }

  // urdfdom links a loop of joints (or a link with two parents) into a cycle of shared pointers
  // that is never freed; both are refused here first, naming the joint.
  void check_tree() const {
    for (const auto& [child, edge] : parent_of_) {
      std::string link = edge.parent;
      for (size_t hops = 0; hops <= parent_of_.size(); ++hops) {
        if (link == child) {
          fail(edge.line, "joint '" + edge.joint + "' closes a loop: link '" + child +
                              "' would be its own ancestor (a URDF is a tree)");
        }
        const auto up = parent_of_.find(link);
        if (up == parent_of_.end()) break;
        link = up->second.parent;
      }
    }
  }

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw UrdfError(source_ + (line > 0 ? " line " + std::to_string(line) : "") + ": " + what);
  }

  // xacro macros, properties and substitutions survive into the text only when it was never
  // expanded; urdfdom would skip the macros and read the rest, silently losing links.
  void check_not_xacro(const TiXmlElement* e) const {
    const std::string kExpand =
        "this is a xacro file: expand it with xacro first "
        "(xacro robot.urdf.xacro > robot.urdf)";
    if (std::strncmp(e->Value(), "xacro:", 6) == 0) {
      fail(e->Row(), std::string("<").append(e->Value()).append(">: ") + kExpand);
    }
    for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string value = a->Value();
      // (xacro's output keeps the xmlns:xacro declaration, so that alone says nothing.)
      if (value.find("${") != std::string::npos || value.find("$(") != std::string::npos) {
        std::ostringstream what;
        what << "<" << e->Value() << " " << a->Name() << "='" << value << "'>: " << kExpand;
        fail(e->Row(), what.str());
      }
    }
    for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      check_not_xacro(c);
    }
  }

  void check_numbers(const TiXmlElement* e, const std::string& label, const std::string& path) {
    std::vector<double> values;
    for (const NumericAttribute& spec : kNumeric) {
      if (std::strcmp(e->Value(), spec.element) != 0) continue;
      const char* text = e->Attribute(spec.attribute);
      if (text == nullptr) continue;
      const std::string where =
          label + " " + path + "<" + e->Value() + " " + spec.attribute + "='" + text + "'>";
      if (!parse_numbers(text, values)) fail(e->Row(), where + ": not a number");
      if (static_cast<int>(values.size()) != spec.count) {
        fail(e->Row(), where + ": needs " + std::to_string(spec.count) +
                           (spec.count == 1 ? " number" : " numbers") + ", has " +
                           std::to_string(values.size()));
      }
      for (double v : values) {
        if (spec.positive && !(v > 0)) fail(e->Row(), where + ": must be > 0");
      }
    }
    for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      check_numbers(c, label, path + "<" + e->Value() + ">");
    }
  }

  std::string source_;
  UrdfOutline outline_;
  std::map<std::string, Edge> parent_of_;  // child link → the first joint naming it as child
};

std::string line_suffix(int line) {
  return line > 0 ? " (line " + std::to_string(line) + ")" : std::string();
}

}  // namespace

std::string UrdfOutline::link_line(const std::string& link) const {
  const auto it = links.find(link);
  return it == links.end() ? std::string() : line_suffix(it->second.line);
}

std::string UrdfOutline::joint_line(const std::string& joint) const {
  const auto it = joint_lines.find(joint);
  return it == joint_lines.end() ? std::string() : line_suffix(it->second);
}

UrdfOutline outline_urdf(const std::string& xml, const std::string& source) {
  return Outliner(source).run(xml);
}

}  // namespace kinograph::dynamics
