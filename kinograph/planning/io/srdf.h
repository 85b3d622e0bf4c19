#pragma once
// The allowed-collision list of a MoveIt-style SRDF: its <disable_collisions link1=".."
// link2=".." reason=".."/> elements, turned into body pairs of a robot Model. Other SRDF
// elements (groups, virtual joints, end effectors) are not read.
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kinograph/dynamics/model.h"

namespace kinograph::planning {

/// An SRDF that cannot be used: unreadable, not well-formed XML, a root other than `<robot>`, a
/// disable_collisions without link1 or link2, or a link the robot does not have. what() names
/// the file, the line and the element.
class SrdfError : public std::runtime_error {
 public:
  SrdfError(std::string file, int line, const std::string& message);
  const std::string& file() const { return file_; }
  /// 1-based line of the offending element, 0 when unknown.
  int line() const { return line_; }

 private:
  std::string file_;
  int line_ = 0;
};

/// One `<disable_collisions>` element: a link pair allowed to touch.
struct DisabledCollision {
  std::string link1, link2;
  std::string reason;  ///< as written ("Adjacent", "Never", ...); may be empty
  int line = 0;        ///< 1-based line of the element
};

/// The disable_collisions elements of SRDF text in file order; `source` names it in errors.
/// @throws SrdfError for malformed XML, a root other than `<robot>` or a missing link attribute.
std::vector<DisabledCollision> parse_srdf(const std::string& xml, const std::string& source = "");

/// Reads an SRDF file's disable_collisions elements. @throws SrdfError as parse_srdf, and
/// when the file cannot be read.
std::vector<DisabledCollision> load_srdf(const std::string& path);

/// The body pairs (Model::bodies indices, −1 = the base) of the elements: a link merged into a
/// body by fixed joints stands for that body. @throws SrdfError naming `source`, the line and
/// the link when the model has no such link.
std::vector<std::pair<int, int>> allowed_body_pairs(const dynamics::Model& model,
                                                    const std::vector<DisabledCollision>& list,
                                                    const std::string& source);

}  // namespace kinograph::planning
