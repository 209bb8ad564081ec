#pragma once

#include <fenv.h>

namespace grainflow {

// OpenFOAM traps floating-point exceptions (FOAM_SIGFPE): an overflow or a 0/0 anywhere ends
// the process with a stack trace and no word on why. Code that checks its own results instead
// -- the DEM's finite guard, grainFoam's divergence check after each fluid solve -- runs in
// the scope of one of these: the traps are off while it lives and restored (with the flags
// raised meanwhile cleared) when it ends.
class FloatingPointTrapsOff {
 public:
  FloatingPointTrapsOff() : traps_(fegetexcept()) {
    if (traps_ != 0) fedisableexcept(traps_);
  }
  ~FloatingPointTrapsOff() {
    if (traps_ == 0) return;
    feclearexcept(FE_ALL_EXCEPT);
    feenableexcept(traps_);
  }
  FloatingPointTrapsOff(const FloatingPointTrapsOff&) = delete;
  FloatingPointTrapsOff& operator=(const FloatingPointTrapsOff&) = delete;

 private:
  int traps_;
};

}  // namespace grainflow
