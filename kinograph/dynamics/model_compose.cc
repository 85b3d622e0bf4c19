#include "kinograph/dynamics/model_compose.h"

#include <set>
#include <stdexcept>

#include "kinograph/dynamics/base_placement.h"

namespace kinograph::dynamics {

std::string composed_name(const std::string& robot, const std::string& name) {
  return robot + kComposeSeparator + name;
}

Model compose(const std::vector<ComposedPart>& parts, std::vector<ComposedRange>* ranges) {
  if (parts.empty()) throw std::invalid_argument("a composite needs at least one robot");
  std::set<std::string> names;
  Model out;
  if (ranges) ranges->clear();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const ComposedPart& part = parts[i];
    if (part.name.empty())
      throw std::invalid_argument("robot " + std::to_string(i) + " has no name");
    if (part.name.find(kComposeSeparator) != std::string::npos) {
      throw std::invalid_argument("robot name '" + part.name + "' must not contain '" +
                                  std::string(1, kComposeSeparator) + "'");
    }
    if (!names.insert(part.name).second) {
      throw std::invalid_argument("two robots are named '" + part.name + "'");
    }
    if (!part.model) throw std::invalid_argument("robot '" + part.name + "' has no model");
    if (i == 0) {
      out.gravity = part.model->gravity;
    } else if (!part.model->gravity.isApprox(out.gravity, 1e-12)) {
      throw std::invalid_argument("robot '" + part.name + "' has a gravity different from robot '" +
                                  parts[0].name + "'s: one cell has one gravity");
    }
    Model placed;
    try {
      placed = place_base(*part.model, part.world_from_base);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("robot '" + part.name + "': " + e.what());
    }
    ComposedRange range{part.name,
                        out.nq(),
                        placed.nq(),
                        static_cast<int>(out.collision.size()),
                        static_cast<int>(placed.collision.size()),
                        static_cast<int>(out.visual.size()),
                        static_cast<int>(placed.visual.size())};
    const int offset = range.offset;
    const auto shift = [offset](int body) { return body < 0 ? body : body + offset; };
    for (Body b : placed.bodies) {
      b.name = composed_name(part.name, b.name);
      b.joint_name = composed_name(part.name, b.joint_name);
      b.parent = shift(b.parent);
      out.bodies.push_back(std::move(b));
    }
    for (Frame f : placed.frames) {
      f.name = composed_name(part.name, f.name);
      f.body = shift(f.body);
      out.frames.push_back(std::move(f));
    }
    for (auto [from, to] :
         {std::pair{&placed.collision, &out.collision}, std::pair{&placed.visual, &out.visual}}) {
      for (Geometry g : *from) {
        g.body = shift(g.body);
        g.link_name = composed_name(part.name, g.link_name);
        to->push_back(std::move(g));
      }
    }
    out.base_mass += placed.base_mass;
    out.name += (i == 0 ? "" : "+") + part.name;
    if (ranges) ranges->push_back(range);
  }
  return out;
}

}  // namespace kinograph::dynamics
