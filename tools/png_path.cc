#include "tools/png_path.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace kinograph::tools {

CLI::Validator png_path() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        std::string ext = std::filesystem::path(path).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (ext == ".png") return {};
        return "'" + path + "': pictures are written as PNG only; name the file .png";
      },
      "PNG");
}

}  // namespace kinograph::tools
