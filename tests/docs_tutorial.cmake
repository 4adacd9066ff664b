# Renders every step of the scene tutorial (docs/guide/tutorial/*.json) at
# 32x32 with `beamcast render`: each must render and write its PNG.
#   cmake -DBEAMCAST=... -DDIR=docs/guide/tutorial -DOUT=... -P docs_tutorial.cmake
file(GLOB steps "${DIR}/*.json")
list(LENGTH steps count)
if(count LESS 6)
  message(FATAL_ERROR "expected the tutorial's 6 steps in ${DIR}, found ${count}")
endif()
foreach(step IN LISTS steps)
  get_filename_component(name "${step}" NAME_WE)
  file(REMOVE_RECURSE "${OUT}/${name}")
  execute_process(COMMAND "${BEAMCAST}" render "${step}" --size 32x32 --out "${OUT}/${name}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: beamcast render failed (${rc}):\n${out}\n${err}")
  endif()
  if(NOT EXISTS "${OUT}/${name}/view.png")
    message(FATAL_ERROR "${name}: no view.png in ${OUT}/${name}")
  endif()
  message(STATUS "${name}: rendered")
endforeach()
