# check_doc.cmake - fails when the copy of minimal.cpp in docs/embedding.md
# (between the "minimal.cpp: begin/end" markers) differs from the file, so the
# documented sample is always the one that compiles and runs.
#   cmake -DDOC=docs/embedding.md -DSOURCE=examples/embed/minimal.cpp -P check_doc.cmake
file(READ ${DOC} doc)
file(READ ${SOURCE} source)
set(begin "<!-- minimal.cpp: begin -->\n```cpp\n")
set(end "```\n<!-- minimal.cpp: end -->")
string(FIND "${doc}" "${begin}" first)
string(FIND "${doc}" "${end}" last)
if(first EQUAL -1 OR last EQUAL -1)
  message(FATAL_ERROR "${DOC}: the minimal.cpp markers are missing")
endif()
string(LENGTH "${begin}" begin_length)
math(EXPR first "${first} + ${begin_length}")
math(EXPR length "${last} - ${first}")
string(SUBSTRING "${doc}" ${first} ${length} quoted)
if(NOT quoted STREQUAL source)
  message(FATAL_ERROR "${DOC} quotes a different minimal.cpp than ${SOURCE}: copy the file into the doc")
endif()
message(STATUS "${DOC} quotes ${SOURCE} exactly")
