#pragma once
// Gidaspow (1994), Multiphase Flow and Fluidization, Academic Press, ch. 5:
// Ergun (dem/fluid/ergun.hpp) for ε < 0.8, Wen–Yu (dem/fluid/wen_yu.hpp) for ε >= 0.8.
// Re = ρ_f ε d U/μ in the Wen–Yu branch. Mean-pressure part: excluded (model-A β).
// The switch is a jump, not a blend: at ε = 0.8 and Re → 0 the Ergun branch gives
// K/(3πμd) = 25/12 = 2.083 and Wen–Yu 0.8^{−2.65} = 1.806 (Wen–Yu/Ergun = 0.867).
#include "dem/fluid/ergun.hpp"
#include "dem/fluid/wen_yu.hpp"

namespace grainflow {

inline constexpr double kGidaspowSwitch = 0.8;

inline double gidaspow(const DragInput& in) {
  return in.void_fraction < kGidaspowSwitch ? ergun(in) : wen_yu(in);
}

}  // namespace grainflow
