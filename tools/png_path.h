#pragma once
// Pictures are written as PNG only: an --out naming another format is refused rather than
// written as PNG under a misleading name.
#include <CLI/CLI.hpp>

namespace kinograph::tools {

/// Validator of an output picture path: it must end in .png (any case).
CLI::Validator png_path();

}  // namespace kinograph::tools
