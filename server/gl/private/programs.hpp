// Dermis GL shell (internal) — compiles and links the programs of shaders/ for the render thread.
// Each source is "#version 430 core", the variant's #defines, shaders/common.glsl, the stage's
// includes, then the file.
// Needs a current GL context; fails with ErrorCode::Internal and the driver's info log.
#pragma once

#include "core/result.hpp"

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dermis::gl {

struct ProgramDesc {
    std::vector<std::pair<unsigned, std::string_view>> stages; ///< GL shader type → file name
    std::vector<std::string> defines;                         ///< e.g. "DERMIS_TESSELLATED"
    std::vector<const char*> feedbackVaryings;                ///< interleaved transform feedback
    /// Files inserted after common.glsl into the stages of one GL shader type (e.g. pbr.glsl
    /// into the fragment stage), in order.
    std::vector<std::pair<unsigned, std::string_view>> includes;
};

/// Returns the linked program object (owned by the caller: glDeleteProgram).
Result<unsigned> buildProgram(const ProgramDesc& desc);

} // namespace dermis::gl
