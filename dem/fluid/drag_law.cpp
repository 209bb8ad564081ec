#include "dem/fluid/drag_law.hpp"

#include <limits>

#include "dem/fluid/beetstra.hpp"
#include "dem/fluid/di_felice.hpp"
#include "dem/fluid/ergun.hpp"
#include "dem/fluid/gidaspow.hpp"
#include "dem/fluid/koch_hill.hpp"
#include "dem/fluid/rong.hpp"
#include "dem/fluid/schiller_naumann.hpp"
#include "dem/fluid/tenneti_garg_subramaniam.hpp"
#include "dem/fluid/wen_yu.hpp"

namespace grainflow {

const std::vector<DragLaw>& drag_laws() {
  // The Newton regime's C_D = 0.44 of the dilute laws ends at the drag crisis (Re ~ 2e5;
  // Clift, Grace & Weber 1978, ch. 5).
  constexpr double crisis = 2e5;
  constexpr const char* newton =
      "C_D = 0.44 holds up to the drag crisis (Clift, Grace & Weber 1978)";
  static const std::vector<DragLaw> laws = {
      {"schiller_naumann", schiller_naumann, "Schiller & Naumann 1933", false, crisis, newton,
       true},
      {"di_felice", di_felice, "Di Felice 1994", false, 1e4,
       "Di Felice 1994 fitted data from Re = 0.01 to 1e4"},
      {"rong", rong, "Rong, Dong & Yu 2013", false, 1000,
       "Rong, Dong & Yu 2013 simulated Re up to 1000"},
      {"wen_yu", wen_yu, "Wen & Yu 1966 (Gidaspow 1994 form)", false, crisis, newton},
      {"ergun", ergun, "Ergun 1952 (Gidaspow 1994 form)", false,
       std::numeric_limits<double>::infinity(), ""},
      {"gidaspow", gidaspow, "Gidaspow 1994 (Ergun below eps = 0.8, Wen-Yu above)", false, crisis,
       newton},
      {"koch_hill", koch_hill, "Koch & Hill 2001", true, 200,
       "the lattice-Boltzmann data of Hill, Koch & Ladd 2001 reach Re_a = Re/2 of order 100"},
      {"beetstra", beetstra, "Beetstra, van der Hoef & Kuipers 2007, eq. 16", false, 1000,
       "Beetstra et al. 2007 fitted Re up to 1000"},
      {"tenneti_garg_subramaniam", tenneti_garg_subramaniam, "Tenneti, Garg & Subramaniam 2011",
       true, 300, "Tenneti et al. 2011 fitted Re from 0.01 to 300"},
  };
  return laws;
}

std::vector<std::string> drag_law_names() {
  std::vector<std::string> names;
  for (const DragLaw& law : drag_laws()) names.emplace_back(law.name);
  return names;
}

const DragLaw& drag_law(std::string_view name) {
  for (const DragLaw& law : drag_laws())
    if (name == law.name) return law;
  std::string all;
  for (const DragLaw& law : drag_laws()) all += std::string(all.empty() ? "" : ", ") + law.name;
  throw UnknownDragLaw("unknown drag law '" + std::string(name) + "'; allowed: " + all);
}

}  // namespace grainflow
