# Embeds the GLSL sources into a C++ file at build time (cmake -P):
#   cmake -DOUT=<file.cpp> -DFILES="a.vert;b.frag;..." -P embed.cmake
# Each file becomes one entry of dermis::gl::shaderSources() under its file name.
set(body "// Generated from shaders/ by shaders/embed.cmake; do not edit.\n")
string(APPEND body "#include \"shader_sources.hpp\"\n\nnamespace dermis::gl {\n\n")
string(APPEND body "const std::vector<ShaderSource>& shaderSources() {\n")
string(APPEND body "    static const std::vector<ShaderSource> sources = {\n")
foreach(f IN LISTS FILES)
  file(READ "${f}" text)
  get_filename_component(name "${f}" NAME)
  string(APPEND body "        {\"${name}\", R\"dermis_glsl(${text})dermis_glsl\"},\n")
endforeach()
string(APPEND body "    };\n    return sources;\n}\n\n} // namespace dermis::gl\n")
file(WRITE "${OUT}.tmp" "${body}")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
