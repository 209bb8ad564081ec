#include "dem/fluid/drag_law.hpp"

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
  static const std::vector<DragLaw> laws = {
      {"schiller_naumann", schiller_naumann, "Schiller & Naumann 1933", false},
      {"di_felice", di_felice, "Di Felice 1994", false},
      {"rong", rong, "Rong, Dong & Yu 2013", false},
      {"wen_yu", wen_yu, "Wen & Yu 1966 (Gidaspow 1994 form)", false},
      {"ergun", ergun, "Ergun 1952 (Gidaspow 1994 form)", false},
      {"gidaspow", gidaspow, "Gidaspow 1994 (Ergun below eps = 0.8, Wen-Yu above)", false},
      {"koch_hill", koch_hill, "Koch & Hill 2001", true},
      {"beetstra", beetstra, "Beetstra, van der Hoef & Kuipers 2007, eq. 16", false},
      {"tenneti_garg_subramaniam", tenneti_garg_subramaniam,
       "Tenneti, Garg & Subramaniam 2011", true},
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
