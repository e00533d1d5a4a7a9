# Embeds a text file as a C++ string_view function at build time (cmake -P):
#   cmake -DIN=<file> -DOUT=<file.cpp> -DFUNCTION=<qualified name> -DHEADER=<include> -P embed_text.cmake
file(READ "${IN}" text)
set(body "// Generated from ${IN} by embed_text.cmake; do not edit.\n#include \"${HEADER}\"\n\n")
string(APPEND body "std::string_view ${FUNCTION}() {\n    static const char text[] = R\"dermis_text(${text})dermis_text\";\n")
string(APPEND body "    return {text, sizeof(text) - 1};\n}\n")
file(WRITE "${OUT}.tmp" "${body}")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
