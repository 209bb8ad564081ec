// The translation unit that compiles tests/support/test_pch.hpp into the tests' precompiled
// header (tests/CMakeLists.txt); it defines nothing.
#include "tests/support/test_pch.hpp"
