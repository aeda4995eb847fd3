// The view's up axis: parsing and the rotation onto render space's +y.
#include "footfall/viewer/view_up.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <vector>

#include "footfall/client/query_text.h"

namespace footfall::viewer {
namespace {

const char* const kExpected =
    "expected an axis: x, y, z, -x, -y or -z, or a vector along one (0,0,1 for Z up)";

}  // namespace

bool ParseViewUp(const std::string& text, ViewUp* up, std::string* error) {
  std::string lower;
  for (const char c : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool negative = !lower.empty() && lower[0] == '-';
  const std::string name = negative ? lower.substr(1) : lower;
  if (name == "x" || name == "y" || name == "z") {
    *up = {name[0] - 'x', negative ? -1 : 1};
    return true;
  }
  std::vector<double> v;
  std::istringstream in(text);
  for (std::string token; std::getline(in, token, ',');) {
    double x = 0;
    if (!ParseFiniteNumber(token, &x)) break;
    v.push_back(x);
  }
  int along = -1, nonzero = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i] != 0) along = static_cast<int>(i), ++nonzero;
  }
  // (A last empty field is dropped by getline: "0,0,1," is refused by the count of commas.)
  const size_t commas = static_cast<size_t>(std::count(text.begin(), text.end(), ','));
  if (v.size() == 3 && commas == 2 && nonzero == 1) {
    *up = {along, v[static_cast<size_t>(along)] > 0 ? 1 : -1};
    return true;
  }
  *error = "--up \"" + text + "\": " + kExpected +
           (v.size() == 3 && commas == 2 && nonzero > 1
                ? "; the view stands on an axis (a tilted up is not drawn)"
                : "");
  return false;
}

Vec3 UpVector(const ViewUp& up) {
  Vec3 v{};
  (up.axis == 0 ? v.x : up.axis == 1 ? v.y : v.z) = up.sign;
  return v;
}

glm::dmat3 RenderRotation(const ViewUp& up) {
  // Rows of the rotation (glm is column-major: built transposed). Each takes `up` to +y and
  // keeps the handedness: Z up turns as glTF's Y-up convention does, (x, y, z) -> (x, z, -y).
  glm::dmat3 rows(1.0);
  const double s = up.sign;
  if (up.axis == 1) {
    rows = glm::dmat3(1, 0, 0, 0, s, 0, 0, 0, s);  // -y: half a turn about x
  } else if (up.axis == 2) {
    rows = glm::dmat3(1, 0, 0, 0, 0, s, 0, -s, 0);
  } else {
    rows = glm::dmat3(0, -s, 0, s, 0, 0, 0, 0, 1);
  }
  return glm::transpose(rows);
}

}  // namespace footfall::viewer
