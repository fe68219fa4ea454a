# A library must not change the process around it: no binary or module of gilt defines the
# global operator new or delete (it once replaced them to order CGAL's allocations; see
# radiosity/mesh/imprint.h for what does that job now). Run as
#   cmake -DNM=nm "-DFILES=a;b" -P no_replaced_allocator.cmake
foreach(file ${FILES})
  execute_process(COMMAND ${NM} -C --defined-only ${file} OUTPUT_VARIABLE symbols RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${NM} could not read ${file}")
  endif()
  string(REGEX MATCHALL "[^\n]*operator (new|delete)[^\n]*" found "${symbols}")
  if(found)
    message(FATAL_ERROR "${file} defines the global allocator:\n${found}")
  endif()
  message(STATUS "${file}: no operator new or delete defined")
endforeach()
