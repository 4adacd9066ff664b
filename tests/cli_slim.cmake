# `beamcast slim fit`: a cube written as OFF (quads: fans), the JSON report on
# stdout, the model file read back by its size, and a malformed file's error.
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(WRITE ${OUT}/cube.off "OFF\n8 6 0\n-1 -1 -1\n1 -1 -1\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n")
execute_process(COMMAND ${BEAMCAST} slim fit ${OUT}/cube.off --out ${OUT}/cube.bslm --error 0.02
                        --samples 20000
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "beamcast slim fit exited ${rc}: ${err}")
endif()
string(JSON spheres GET "${out}" spheres)
string(JSON creases GET "${out}" creases)
string(JSON uncovered GET "${out}" uncovered)
string(JSON error_rms GET "${out}" error_rms)
foreach(key error_mean error_max seconds)
  string(JSON value GET "${out}" ${key})
endforeach()
if(spheres LESS 8 OR creases LESS 1 OR NOT uncovered EQUAL 0)
  message(FATAL_ERROR "unexpected report: ${out}")
endif()
if(error_rms GREATER 0.02)
  message(FATAL_ERROR "rms error ${error_rms} above E = 0.02: ${out}")
endif()
# Binary model: 16 bytes of header and 84 per sphere.
file(SIZE ${OUT}/cube.bslm size)
math(EXPR expected "16 + 84 * ${spheres}")
if(NOT size EQUAL expected)
  message(FATAL_ERROR "cube.bslm has ${size} bytes, expected ${expected}")
endif()

file(WRITE ${OUT}/bad.off "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n")
execute_process(COMMAND ${BEAMCAST} slim fit ${OUT}/bad.off --out ${OUT}/bad.bslm
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "bad.off:6: vertex index 9 out of range")
  message(FATAL_ERROR "bad.off: exit ${rc}, stderr: ${err}")
endif()
