# Run by `cmake --install` (cmake/bifilar_install.cmake sets BIFILAR_SOURCE_DIR,
# BIFILAR_PUBLIC_HEADERS and BIFILAR_INCLUDE_DESTINATION first): copies each public header to
# <prefix>/include/bifilar/<path>, its includes of bifilar's own headers ("fit/trace_fit.h")
# rewritten to the installed prefix ("bifilar/fit/trace_fit.h"). The sources keep including from
# the repository root. Fails, naming both, when a public header includes a header of the tree
# that is not public: an installed header must compile with the installed headers alone.
set(bifilar_root "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/${BIFILAR_INCLUDE_DESTINATION}/bifilar")
if(IS_ABSOLUTE "${BIFILAR_INCLUDE_DESTINATION}")
  set(bifilar_root "$ENV{DESTDIR}${BIFILAR_INCLUDE_DESTINATION}/bifilar")
endif()
set(bifilar_own_folders "base|pendulum|fit|pipeline")
set(bifilar_problems "")
foreach(header IN LISTS BIFILAR_PUBLIC_HEADERS)
  set(source "${BIFILAR_SOURCE_DIR}/${header}")
  if(NOT EXISTS "${source}")
    message(FATAL_ERROR "bifilar install: public header ${header} does not exist "
                        "(BIFILAR_PUBLIC_HEADERS in cmake/bifilar_install.cmake)")
  endif()
  file(READ "${source}" text)
  # Every quoted include of the tree must be public; angle-bracket includes are other libraries'.
  string(REGEX MATCHALL "#include \"(${bifilar_own_folders})/[^\"]+\"" includes "${text}")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "#include \"([^\"]+)\"" "\\1" included "${line}")
    list(FIND BIFILAR_PUBLIC_HEADERS "${included}" index)  # no IN_LIST: no policies here
    if(index EQUAL -1)
      string(APPEND bifilar_problems "\n  ${header} includes ${included}, which is not public")
    endif()
  endforeach()
  string(REGEX REPLACE "#include \"(${bifilar_own_folders})/" "#include \"bifilar/\\1/" text
         "${text}")
  set(target "${bifilar_root}/${header}")
  message(STATUS "Installing: ${target}")
  get_filename_component(folder "${target}" DIRECTORY)
  file(MAKE_DIRECTORY "${folder}")
  file(WRITE "${target}" "${text}")
  list(APPEND CMAKE_INSTALL_MANIFEST_FILES "${target}")
endforeach()
if(bifilar_problems)
  message(FATAL_ERROR "bifilar install: a public header includes a header that is not installed:"
                      "${bifilar_problems}\nAdd it to BIFILAR_PUBLIC_HEADERS in "
                      "cmake/bifilar_install.cmake (or stop including it from the public one).")
endif()
