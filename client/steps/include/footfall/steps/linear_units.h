// Linear units a walk's lengths may be in (Walk::unit), named as Maya's `currentUnit -linear`
// names them (mm, cm, m, km, in, ft, yd, mi): the MEL export sets Maya's unit to one, the glTF
// export converts from one to metres.
#pragma once

#include <string>

namespace footfall {

// Metres in one `unit` (0.01 for "cm", 0.0254 for "in"); 0 when `unit` is none of them.
double MetresPerLinearUnit(const std::string& unit);

// The units MetresPerLinearUnit knows, for messages: "mm, cm, m, km, in, ft, yd or mi".
const char* LinearUnitNames();

}  // namespace footfall
