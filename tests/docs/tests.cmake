# Documentation checks (included by tests/CMakeLists.txt).

# docs.references: every Markdown link and anchor, every repository path a page names in
# backticks, and every page (and section) the sources name in messages, --help and comments
# leads somewhere (tests/docs/check_references.py; the standard library only).
grainflow_find_python(GRAINFLOW_DOCS_PYTHON "re" "docs.references is")
if(GRAINFLOW_DOCS_PYTHON)
  add_test(NAME docs.references
           COMMAND ${GRAINFLOW_DOCS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_references.py
                   ${PROJECT_SOURCE_DIR})
  set_tests_properties(docs.references PROPERTIES LABELS docs TIMEOUT 60)
endif()
