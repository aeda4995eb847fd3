// Quaternion to Euler XYZ and ZXY conversion: the angles rebuild the same rotation, including at
// gimbal lock, and unwrapping picks the equivalent triple nearest the previous key.
#include <cmath>
#include <random>
#include <vector>

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

TEST_CASE("At gimbal lock the turn is split as the neighbouring key splits it", "[export][euler]") {
  // A Z-up body facing -Y is at lock in ZXY (x = 90): its first key was (90, 0, 0), the next
  // after a turn (60, 90, 90), and Maya's per-angle interpolation leaned the body up to 10
  // degrees between them.
  const Quat z_up = AxisAngle({1, 0, 0}, 90);
  SECTION("ClosestEulerZxyDegrees keeps the rotation and nears the previous key") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> angle(-400, 400);
    for (double x : {90.0, -90.0}) {
      for (int i = 0; i < 200; ++i) {
        const Vec3 locked = QuatToEulerZxyDegrees(FromEulerZxy({x, angle(rng), angle(rng)}));
        REQUIRE(std::abs(locked.x) == Approx(90));
        const Vec3 previous{x, angle(rng), angle(rng)};
        const Vec3 e = ClosestEulerZxyDegrees(locked, previous);
        CHECK(AbsDot(FromEulerZxy(e), FromEulerZxy(locked)) == Approx(1).margin(1e-9));
        // No other split of the turn, nor whole turns added, comes nearer.
        const double s = x > 0 ? 1 : -1;
        const double d = std::abs(e.y - previous.y) + std::abs(e.z - previous.z);
        for (double t = -360; t <= 360; t += 7.5) {
          for (int wy = -2; wy <= 2; ++wy) {
            const double y = locked.y + s * t + 360 * wy;
            for (int wz = -2; wz <= 2; ++wz) {
              const double z = locked.z + t + 360 * wz;
              CHECK(d <= std::abs(y - previous.y) + std::abs(z - previous.z) + 1e-9);
            }
          }
        }
      }
    }
  }
  SECTION("ContinuousEulerZxyDegrees: keys at lock before the first that is not") {
    const Quat facing_minus_y = Multiply(AxisAngle({0, 0, 1}, 180), z_up);
    const Quat turned = Multiply(AxisAngle({0, 0, 1}, 150), z_up);
    const std::vector<Vec3> e = ContinuousEulerZxyDegrees({facing_minus_y, facing_minus_y, turned});
    REQUIRE(e.size() == 3);
    REQUIRE(std::abs(e[0].x) == Approx(90));
    REQUIRE(std::abs(e[2].x) != Approx(90));
    for (size_t k = 0; k < 3; ++k)
      CHECK(AbsDot(FromEulerZxy(e[k]), k < 2 ? facing_minus_y : turned) == Approx(1).margin(1e-9));
    // Halfway between the keys, Maya's angles give a body turning about Z alone: it stays up.
    const Vec3 mid{(e[1].x + e[2].x) / 2, (e[1].y + e[2].y) / 2, (e[1].z + e[2].z) / 2};
    const Quat q = FromEulerZxy(mid);
    // The body's up (+Y) in the world: 1 - 2(x^2 + z^2) etc. of the rotation's second column.
    const Vec3 up{2 * (q.x * q.y - q.z * q.w), 1 - 2 * (q.x * q.x + q.z * q.z),
                  2 * (q.y * q.z + q.x * q.w)};
    CHECK(up.z == Approx(1).margin(1e-9));
    CHECK(e[0].y == Approx(e[1].y));
    CHECK(e[0].z == Approx(e[1].z));
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
