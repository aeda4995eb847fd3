// Quaternion to Euler XYZ and ZXY conversion: the angles rebuild the same rotation, including at
// gimbal lock, and unwrapping picks the equivalent triple nearest the previous key.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "footfall/export/euler.h"

using namespace footfall;

namespace {

constexpr double kPi = 3.14159265358979323846;

Quat Multiply(const Quat& a, const Quat& b) {
  return {
      a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
      a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

Quat AxisAngle(const Vec3& axis, double degrees) {
  const double half = degrees * kPi / 360;
  return {axis.x * std::sin(half), axis.y * std::sin(half), axis.z * std::sin(half),
          std::cos(half)};
}

// Maya XYZ order: X first, then Y, then Z, about the parent axes.
Quat FromEulerXyz(const Vec3& e) {
  return Multiply(AxisAngle({0, 0, 1}, e.z),
                  Multiply(AxisAngle({0, 1, 0}, e.y), AxisAngle({1, 0, 0}, e.x)));
}

// Maya ZXY order: Z first, then X, then Y, about the parent axes.
Quat FromEulerZxy(const Vec3& e) {
  return Multiply(AxisAngle({0, 1, 0}, e.y),
                  Multiply(AxisAngle({1, 0, 0}, e.x), AxisAngle({0, 0, 1}, e.z)));
}

double AbsDot(const Quat& a, const Quat& b) {
  const double n = std::sqrt(b.x * b.x + b.y * b.y + b.z * b.z + b.w * b.w);
  return std::abs(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w) / n;
}

}  // namespace

TEST_CASE("QuatToEulerXyzDegrees rebuilds the rotation", "[export][euler]") {
  SECTION("known angles") {
    const Vec3 e = QuatToEulerXyzDegrees(FromEulerXyz({10, 20, 30}));
    CHECK(e.x == Approx(10));
    CHECK(e.y == Approx(20));
    CHECK(e.z == Approx(30));
    const Vec3 yaw = QuatToEulerXyzDegrees(AxisAngle({0, 1, 0}, -45));
    CHECK(yaw.x == Approx(0).margin(1e-12));
    CHECK(yaw.y == Approx(-45));
    CHECK(yaw.z == Approx(0).margin(1e-12));
  }
  SECTION("random rotations, not unit length") {
    std::mt19937 rng(7);
    std::normal_distribution<double> normal;
    for (int i = 0; i < 1000; ++i) {
      const Quat q{normal(rng), normal(rng), normal(rng), normal(rng)};
      const Vec3 e = QuatToEulerXyzDegrees(q);
      CHECK(e.y >= -90);
      CHECK(e.y <= 90);
      CHECK(AbsDot(FromEulerXyz(e), q) == Approx(1).margin(1e-9));
    }
  }
  SECTION("gimbal lock") {
    const Quat q = FromEulerXyz({25, 90, 40});
    const Vec3 e = QuatToEulerXyzDegrees(q);
    CHECK(e.x == 0);
    CHECK(e.y == Approx(90));
    CHECK(AbsDot(FromEulerXyz(e), q) == Approx(1).margin(1e-9));
  }
}

TEST_CASE("ClosestEulerXyzDegrees unwraps toward the previous key", "[export][euler]") {
  SECTION("adds whole turns") {
    const Vec3 e = ClosestEulerXyzDegrees({0, 0, -170}, {0, 0, 170});
    CHECK(e.z == Approx(190));
    const Vec3 f = ClosestEulerXyzDegrees({5, 10, 15}, {725, 10, -345});
    CHECK(f.x == Approx(725));
    CHECK(f.z == Approx(15 - 360));
  }
  SECTION("takes the alternative solution when it is nearer") {
    const Vec3 previous{180, 100, 180};  // past +90 on Y, reached by unwrapping
    const Vec3 e = ClosestEulerXyzDegrees({0, 80, 0}, previous);
    CHECK(e.x == Approx(180));
    CHECK(e.y == Approx(100));
    CHECK(e.z == Approx(180));
    CHECK(AbsDot(FromEulerXyz(e), FromEulerXyz({0, 80, 0})) == Approx(1).margin(1e-9));
  }
}

TEST_CASE("QuatToEulerZxyDegrees rebuilds the rotation", "[export][euler]") {
  SECTION("known angles") {
    const Vec3 e = QuatToEulerZxyDegrees(FromEulerZxy({10, 20, 30}));
    CHECK(e.x == Approx(10));
    CHECK(e.y == Approx(20));
    CHECK(e.z == Approx(30));
    // Heading is Y alone, whatever it is: +-X (yaw +-90) is no special case.
    for (double yaw : {-45.0, 90.0, -90.0, 180.0}) {
      const Vec3 h = QuatToEulerZxyDegrees(AxisAngle({0, 1, 0}, yaw));
      CHECK(h.x == Approx(0).margin(1e-12));
      CHECK(std::abs(h.y) == Approx(std::abs(yaw)));
      CHECK(h.z == Approx(0).margin(1e-12));
    }
    const Vec3 tilted = QuatToEulerZxyDegrees(FromEulerZxy({-5, 90, 3}));
    CHECK(tilted.x == Approx(-5));
    CHECK(tilted.y == Approx(90));
    CHECK(tilted.z == Approx(3));
  }
  SECTION("random rotations, not unit length") {
    std::mt19937 rng(11);
    std::normal_distribution<double> normal;
    for (int i = 0; i < 1000; ++i) {
      const Quat q{normal(rng), normal(rng), normal(rng), normal(rng)};
      const Vec3 e = QuatToEulerZxyDegrees(q);
      CHECK(e.x >= -90);
      CHECK(e.x <= 90);
      CHECK(std::abs(e.y) <= 180);
      CHECK(std::abs(e.z) <= 180);
      CHECK(AbsDot(FromEulerZxy(e), q) == Approx(1).margin(1e-9));
    }
  }
  SECTION("lengths whose squares overflow or underflow") {
    const Quat q = FromEulerZxy({-5, 90, 3});
    for (double k : {1e300, 1e-200}) {
      INFO(k);
      const Vec3 e = QuatToEulerZxyDegrees({q.x * k, q.y * k, q.z * k, q.w * k});
      CHECK(e.x == Approx(-5));
      CHECK(e.y == Approx(90));
      CHECK(e.z == Approx(3));
      const Vec3 xyz = QuatToEulerXyzDegrees({q.x * k, q.y * k, q.z * k, q.w * k});
      CHECK(std::isfinite(xyz.x));
      CHECK(std::isfinite(xyz.y));
      CHECK(std::isfinite(xyz.z));
    }
  }
  SECTION("gimbal lock") {
    for (double pitch : {90.0, -90.0}) {
      const Quat q = FromEulerZxy({pitch, 25, 40});
      const Vec3 e = QuatToEulerZxyDegrees(q);
      CHECK(e.x == pitch);
      CHECK(e.z == 0);
      CHECK(AbsDot(FromEulerZxy(e), q) == Approx(1).margin(1e-9));
    }
  }
}

TEST_CASE("ClosestEulerZxyDegrees unwraps toward the previous key", "[export][euler]") {
  SECTION("the alternative solution is the same rotation") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> angle(-180, 180);
    for (int i = 0; i < 100; ++i) {
      const Vec3 e{angle(rng) / 2, angle(rng), angle(rng)};
      const Quat q = FromEulerZxy({180 - e.x, e.y + 180, e.z + 180});
      CHECK(AbsDot(FromEulerZxy(e), q) == Approx(1).margin(1e-12));
    }
  }
  SECTION("adds whole turns") {
    const Vec3 e = ClosestEulerZxyDegrees({0, -170, 0}, {0, 170, 0});
    CHECK(e.y == Approx(190));
    const Vec3 f = ClosestEulerZxyDegrees({5, 10, 15}, {5, 730, -345});
    CHECK(f.x == Approx(5));
    CHECK(f.y == Approx(730));
    CHECK(f.z == Approx(15 - 360));
  }
  SECTION("takes the alternative solution when it is nearer") {
    const Vec3 previous{100, 180, 180};  // past +90 on X, reached by unwrapping
    const Vec3 e = ClosestEulerZxyDegrees({80, 0, 0}, previous);
    CHECK(e.x == Approx(100));
    CHECK(e.y == Approx(180));
    CHECK(e.z == Approx(180));
    CHECK(AbsDot(FromEulerZxy(e), FromEulerZxy({80, 0, 0})) == Approx(1).margin(1e-9));
  }
}
