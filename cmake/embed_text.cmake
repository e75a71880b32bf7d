# Writes the text of INPUT into the header OUTPUT as `inline constexpr char NAME[]` (a raw string
# literal), so that a file such as the preview page ships inside the binary. Run as
#   cmake -DINPUT=page.html -DOUTPUT=page.h -DNAME=kPage -P embed_text.cmake
file(READ "${INPUT}" text)
if(text MATCHES "\\)glint_embed\"")
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )glint_embed\"")
endif()
get_filename_component(input_name "${INPUT}" NAME)
file(WRITE "${OUTPUT}.new"
  "// Generated from ${input_name} by cmake/embed_text.cmake at build time; edit that file.\n"
  "#pragma once\n\nnamespace glint {\n\n"
  "inline constexpr char ${NAME}[] = R\"glint_embed(${text})glint_embed\";\n\n}  // namespace glint\n")
file(COPY_FILE "${OUTPUT}.new" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.new")
