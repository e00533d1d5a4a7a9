// Dermis GL shell — the GLSL sources of shaders/, embedded into the binary at build time by
// shaders/embed.cmake (so the server needs no files at run time).
#pragma once

#include <string_view>
#include <vector>

namespace dermis::gl {

struct ShaderSource {
    std::string_view name; ///< file name in shaders/, e.g. "skin.vert"
    std::string_view text; ///< the file's text, without "#version"
};

/// Every embedded file, in the order CMake listed them.
const std::vector<ShaderSource>& shaderSources();

/// The text of shaders/<name>; empty when there is no such file.
std::string_view shaderSource(std::string_view name);

} // namespace dermis::gl
