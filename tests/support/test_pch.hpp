// The headers most test files include, compiled once for all of them (a precompiled header,
// tests/CMakeLists.txt): parsing them took about two thirds of each test file's compile time.
// Only what many tests include belongs here; a test must still include what it uses.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/scene/scene_parser.hpp"
#include "tests/dem/support/test_scene.hpp"
