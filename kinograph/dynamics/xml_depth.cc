#include "kinograph/dynamics/xml_depth.h"

#include <algorithm>
#include <cctype>

namespace kinograph::dynamics {
namespace {

// A cursor over the text that counts the lines it passes.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  bool done() const { return pos_ >= text_.size(); }
  char at(size_t offset = 0) const {
    return pos_ + offset < text_.size() ? text_[pos_ + offset] : '\0';
  }
  bool starts_with(std::string_view s) const { return text_.substr(pos_).starts_with(s); }
  int line() const { return line_; }
  void advance(size_t n) {
    const size_t end = std::min(text_.size(), pos_ + n);
    line_ += static_cast<int>(std::count(text_.begin() + pos_, text_.begin() + end, '\n'));
    pos_ = end;
  }
  // Moves past the next `s` (to the end when there is none).
  void skip_past(std::string_view s) {
    const size_t found = text_.find(s, pos_);
    advance(found == std::string_view::npos ? text_.size() : found - pos_ + s.size());
  }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int line_ = 1;
};

// Moves past a start tag (the cursor on its '<'); true when it closes itself ("/>").
bool skip_start_tag(Cursor& c) {
  c.advance(1);
  char last = '\0';
  while (!c.done() && c.at() != '>') {
    if (c.at() == '=') {
      c.advance(1);
      while (!c.done() && std::isspace(static_cast<unsigned char>(c.at()))) c.advance(1);
      // As TinyXML: a value is quoted only when the quote follows the '='.
      if (c.at() == '"' || c.at() == '\'') {
        const char quote[] = {c.at(), '\0'};
        c.advance(1);
        c.skip_past(quote);
        last = quote[0];
        continue;
      }
      continue;
    }
    last = c.at();
    c.advance(1);
  }
  c.advance(1);
  return last == '/';
}

}  // namespace

XmlDepth find_nesting_beyond(std::string_view xml, int limit) {
  Cursor c(xml);
  int depth = 0;
  while (!c.done()) {
    if (c.at() != '<') {
      c.advance(1);
    } else if (c.starts_with("<!--")) {
      c.skip_past("-->");
    } else if (c.starts_with("<![CDATA[")) {
      c.skip_past("]]>");
    } else if (c.at(1) == '/') {
      depth = std::max(0, depth - 1);
      c.skip_past(">");
    } else if (c.at(1) == '?' || c.at(1) == '!') {
      c.skip_past(">");
    } else if (std::isalpha(static_cast<unsigned char>(c.at(1))) || c.at(1) == '_' ||
               c.at(1) == ':') {
      const int line = c.line();
      if (!skip_start_tag(c) && ++depth > limit) return {true, line};
    } else {
      c.advance(1);
    }
  }
  return {};
}

}  // namespace kinograph::dynamics
