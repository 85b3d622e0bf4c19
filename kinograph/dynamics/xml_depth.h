#pragma once
// How deep the elements of an XML text nest, found without a parser: TinyXML (under urdfdom)
// descends one C++ call per level, so 50,000 nested elements overflow the stack before it can
// report anything. The URDF reader measures the depth first and refuses deep text.
#include <string_view>

namespace kinograph::dynamics {

/// The first element nested deeper than a limit, or none.
struct XmlDepth {
  bool exceeded = false;  ///< an element deeper than the limit was found
  int line = 0;           ///< 1-based line of that element's start tag
};

/// Scans `xml` as TinyXML reads it (comments, CDATA, declarations, quoted attribute values
/// skipped) and stops at the first element nested deeper than `limit` levels.
XmlDepth find_nesting_beyond(std::string_view xml, int limit);

}  // namespace kinograph::dynamics
