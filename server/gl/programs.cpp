#include "programs.hpp"

#include "shader_sources.hpp"

#include <glad/gl.h>

namespace dermis::gl {

std::string_view shaderSource(std::string_view name) {
    for (const ShaderSource& s : shaderSources())
        if (s.name == name) return s.text;
    return {};
}

namespace {

std::string shaderLog(GLuint shader) {
    GLint len = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetShaderInfoLog(shader, len, nullptr, log.data());
    return log.c_str();
}

std::string programLog(GLuint program) {
    GLint len = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(program, len, nullptr, log.data());
    return log.c_str();
}

} // namespace

Result<unsigned> buildProgram(const ProgramDesc& desc) {
    const char* where = "dermis::gl::buildProgram";
    std::string header = "#version 430 core\n";
    for (const std::string& d : desc.defines)
        header += "#define " + d + "\n";
    header += std::string(shaderSource("common.glsl"));
    GLuint program = glCreateProgram();
    std::vector<GLuint> shaders;
    auto cleanup = [&] {
        for (GLuint s : shaders)
            glDeleteShader(s);
        glDeleteProgram(program);
    };
    for (const auto& [type, file] : desc.stages) {
        const std::string_view body = shaderSource(file);
        if (body.empty()) {
            cleanup();
            return makeError(ErrorCode::Internal, where, std::string(file), "no such embedded shader");
        }
        std::string text = header;
        for (const auto& [stage, include] : desc.includes) {
            if (stage != type) continue;
            const std::string_view inc = shaderSource(include);
            if (inc.empty()) {
                cleanup();
                return makeError(ErrorCode::Internal, where, std::string(include),
                                 "no such embedded shader");
            }
            text += "#line 1\n" + std::string(inc);
        }
        text += "#line 1\n" + std::string(body);
        const char* src = text.c_str();
        GLuint sh = glCreateShader(type);
        shaders.push_back(sh);
        glShaderSource(sh, 1, &src, nullptr);
        glCompileShader(sh);
        GLint ok = 0;
        glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            std::string log = shaderLog(sh);
            cleanup();
            return makeError(ErrorCode::Internal, where, std::string(file), "compile failed: " + log);
        }
        glAttachShader(program, sh);
    }
    if (!desc.feedbackVaryings.empty())
        glTransformFeedbackVaryings(program, static_cast<GLsizei>(desc.feedbackVaryings.size()),
                                    desc.feedbackVaryings.data(), GL_INTERLEAVED_ATTRIBS);
    glLinkProgram(program);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        std::string log = programLog(program);
        std::string files;
        for (const auto& st : desc.stages)
            files += (files.empty() ? "" : "+") + std::string(st.second);
        cleanup();
        return makeError(ErrorCode::Internal, where, files, "link failed: " + log);
    }
    for (GLuint s : shaders) {
        glDetachShader(program, s);
        glDeleteShader(s);
    }
    return static_cast<unsigned>(program);
}

} // namespace dermis::gl
