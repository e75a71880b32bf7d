// Linear RGB colors and the sRGB transfer functions.
#pragma once

#include <algorithm>
#include <cmath>

namespace glint {

// A linear RGB triple. 1 is full intensity for display; light intensities may exceed 1.
struct Color {
  double r = 0;
  double g = 0;
  double b = 0;

  constexpr Color() = default;
  constexpr Color(double red, double green, double blue) : r(red), g(green), b(blue) {}
  constexpr explicit Color(double grey) : r(grey), g(grey), b(grey) {}

  constexpr Color& operator+=(const Color& c) {
    r += c.r;
    g += c.g;
    b += c.b;
    return *this;
  }
  constexpr Color& operator*=(const Color& c) {
    r *= c.r;
    g *= c.g;
    b *= c.b;
    return *this;
  }
  constexpr Color& operator*=(double s) {
    r *= s;
    g *= s;
    b *= s;
    return *this;
  }
  friend constexpr bool operator==(const Color&, const Color&) = default;
};

// The seed's addColor and multiColorByNumber, and the component-wise product for coefficients.
constexpr Color operator+(const Color& a, const Color& c) {
  return {a.r + c.r, a.g + c.g, a.b + c.b};
}
constexpr Color operator-(const Color& a, const Color& c) {
  return {a.r - c.r, a.g - c.g, a.b - c.b};
}
constexpr Color operator*(const Color& a, const Color& c) {
  return {a.r * c.r, a.g * c.g, a.b * c.b};
}
constexpr Color operator*(const Color& a, double s) { return {a.r * s, a.g * s, a.b * s}; }
constexpr Color operator*(double s, const Color& a) { return {a.r * s, a.g * s, a.b * s}; }
constexpr Color operator/(const Color& a, double s) { return {a.r / s, a.g / s, a.b / s}; }
constexpr double maxComponent(const Color& c) { return std::max({c.r, c.g, c.b}); }
constexpr bool isBlack(const Color& c) { return c.r == 0 && c.g == 0 && c.b == 0; }
inline bool isFinite(const Color& c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

// sRGB electro-optical transfer (IEC 61966-2-1), for one channel in [0, 1].
inline double srgbToLinear(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}
inline double linearToSrgb(double linear) {
  return linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

}  // namespace glint
