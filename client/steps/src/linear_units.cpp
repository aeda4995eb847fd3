#include "footfall/steps/linear_units.h"

namespace footfall {

double MetresPerLinearUnit(const std::string& unit) {
  static const struct {
    const char* name;
    double metres;
  } kUnits[] = {{"mm", 0.001},  {"cm", 0.01},   {"m", 1},       {"km", 1000},
                {"in", 0.0254}, {"ft", 0.3048}, {"yd", 0.9144}, {"mi", 1609.344}};
  for (const auto& u : kUnits)
    if (unit == u.name) return u.metres;
  return 0;
}

const char* LinearUnitNames() { return "mm, cm, m, km, in, ft, yd or mi"; }

}  // namespace footfall
