# Provenance: the project version and the git revision are written into every output file.
# The revision is refreshed at every build (not only at configure time) by a script that
# rewrites build_info.cpp only when the revision changed, so nothing rebuilds needlessly.
set(KNIT_BUILD_INFO_CPP ${CMAKE_BINARY_DIR}/generated/build_info.cpp)
add_custom_target(knit_build_info_gen
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_SOURCE_DIR} -DOUTPUT=${KNIT_BUILD_INFO_CPP}
          -DVERSION=${PROJECT_VERSION} -P ${CMAKE_SOURCE_DIR}/cmake/WriteBuildInfo.cmake
  BYPRODUCTS ${KNIT_BUILD_INFO_CPP}
  COMMENT "Refreshing git revision")
