#pragma once
// Pictures of failed plans are marked as such: a red frame round the picture and a red
// banner across its bottom saying why, so a failed plan never passes for a valid one.
#include <optional>
#include <string>

#include "kinograph/planning/plan.h"
#include "render/image.h"

namespace kinograph::render {

/// The banner text for a plan that failed ("FAILED PLAN: " and its first failure, or its solve
/// status and reason), nullopt for a valid plan or one whose file records no verdict (no
/// failures listed and a converged solve).
std::optional<std::string> failure_text(const planning::Plan& plan);

/// Draws the red frame and the banner with `text` onto `image`, scaled to its size.
void mark_failed(Image& image, const std::string& text);

}  // namespace kinograph::render
