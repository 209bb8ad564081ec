#pragma once
// Basic types shared by the whole DEM core. SI units throughout.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace grainflow {

using Vec3 = Eigen::Vector3d;
using GlobalId = std::int64_t;

}  // namespace grainflow
