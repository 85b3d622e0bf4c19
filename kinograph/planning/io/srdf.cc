#include "kinograph/planning/io/srdf.h"

#include <expat.h>

#include <fstream>
#include <memory>
#include <sstream>

namespace kinograph::planning {
namespace {

std::string format_error(const std::string& file, int line, const std::string& message) {
  std::ostringstream os;
  os << "SRDF '" << (file.empty() ? "<text>" : file) << "'";
  if (line > 0) os << " line " << line;
  os << ": " << message;
  return os.str();
}

// Expat callbacks collect the elements; the first problem found is kept and parsing stopped.
struct ParseState {
  XML_Parser parser = nullptr;
  std::vector<DisabledCollision> list;
  int depth = 0;
  int error_line = 0;
  std::string error;
};

void fail(ParseState& st, const std::string& message) {
  st.error_line = static_cast<int>(XML_GetCurrentLineNumber(st.parser));
  st.error = message;
  XML_StopParser(st.parser, XML_FALSE);
}

void on_start(void* user, const XML_Char* name, const XML_Char** attributes) {
  auto& st = *static_cast<ParseState*>(user);
  const std::string element(name);
  if (st.depth++ == 0 && element != "robot") {
    fail(st, "the root element is <" + element + ">, an SRDF's is <robot>");
    return;
  }
  if (element != "disable_collisions") return;
  DisabledCollision d;
  d.line = static_cast<int>(XML_GetCurrentLineNumber(st.parser));
  for (int i = 0; attributes[i] != nullptr; i += 2) {
    const std::string key(attributes[i]), value(attributes[i + 1]);
    if (key == "link1") d.link1 = value;
    if (key == "link2") d.link2 = value;
    if (key == "reason") d.reason = value;
  }
  if (d.link1.empty() || d.link2.empty()) {
    fail(st, std::string("<disable_collisions> needs non-empty 'link1' and 'link2' attributes") +
                 " (missing " + (d.link1.empty() ? "link1" : "link2") + ")");
    return;
  }
  st.list.push_back(std::move(d));
}

void on_end(void* user, const XML_Char*) { --static_cast<ParseState*>(user)->depth; }

}  // namespace

SrdfError::SrdfError(std::string file, int line, const std::string& message)
    : std::runtime_error(format_error(file, line, message)), file_(std::move(file)), line_(line) {}

std::vector<DisabledCollision> parse_srdf(const std::string& xml, const std::string& source) {
  const std::unique_ptr<XML_ParserStruct, decltype(&XML_ParserFree)> parser(
      XML_ParserCreate(nullptr), &XML_ParserFree);
  if (!parser) throw SrdfError(source, 0, "cannot create an XML parser");
  ParseState st;
  st.parser = parser.get();
  XML_SetUserData(parser.get(), &st);
  XML_SetElementHandler(parser.get(), &on_start, &on_end);
  const XML_Status status =
      XML_Parse(parser.get(), xml.data(), static_cast<int>(xml.size()), XML_TRUE);
  if (!st.error.empty()) throw SrdfError(source, st.error_line, st.error);
  if (status != XML_STATUS_OK) {
    throw SrdfError(
        source, static_cast<int>(XML_GetCurrentLineNumber(parser.get())),
        std::string("not well-formed XML: ") + XML_ErrorString(XML_GetErrorCode(parser.get())));
  }
  return st.list;
}

std::vector<DisabledCollision> load_srdf(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SrdfError(path, 0, "cannot open the file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_srdf(text.str(), path);
}

std::vector<std::pair<int, int>> allowed_body_pairs(const dynamics::Model& model,
                                                    const std::vector<DisabledCollision>& list,
                                                    const std::string& source) {
  const auto body_of = [&](const std::string& link, const DisabledCollision& d) {
    try {
      return model.frames[model.frame_index(link)].body;
    } catch (const std::out_of_range&) {
      throw SrdfError(source, d.line,
                      "<disable_collisions link1=\"" + d.link1 + "\" link2=\"" + d.link2 +
                          "\">: robot '" + model.name + "' has no link '" + link + "'");
    }
  };
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(list.size());
  for (const DisabledCollision& d : list)
    pairs.emplace_back(body_of(d.link1, d), body_of(d.link2, d));
  return pairs;
}

}  // namespace kinograph::planning
