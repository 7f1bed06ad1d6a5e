#include "client/report/number_format.h"

#include <charconv>
#include <cmath>
#include <string>
#include <system_error>

#include "common/check.h"

namespace mbopt::report {
namespace {

// "1e-05" -> "1e-5", "2.5e+06" -> "2.5e6": shorter labels that read the same.
std::string TidyExponent(std::string s) {
  const std::size_t e = s.find('e');
  if (e == std::string::npos) return s;
  std::string mantissa = s.substr(0, e);
  std::string exponent = s.substr(e + 1);
  bool negative = false;
  if (!exponent.empty() && (exponent[0] == '+' || exponent[0] == '-')) {
    negative = exponent[0] == '-';
    exponent.erase(0, 1);
  }
  while (exponent.size() > 1 && exponent[0] == '0') exponent.erase(0, 1);
  return mantissa + "e" + (negative ? "-" : "") + exponent;
}

// std::to_chars, unlike snprintf, ignores the C locale: a program that
// called setlocale() still gets '.' as the decimal point in SVG coordinates.
std::string ToChars(double value, std::chars_format format, int precision) {
  char buf[512];  // fixed notation of 1e308 with 8 decimals needs ~320
  const auto [end, error] = std::to_chars(buf, buf + sizeof buf, value, format, precision);
  MBOPT_CHECK(error == std::errc(), "number does not fit the format buffer");
  return std::string(buf, end);
}

std::string General(double value, int significant) {
  return ToChars(value, std::chars_format::general, significant);
}

std::string Fixed(double value, int decimals) { return ToChars(value, std::chars_format::fixed, decimals); }

}  // namespace

std::string FormatValue(double value, int significant, const char* missing) {
  if (std::isnan(value)) return missing;
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return TidyExponent(General(value, significant));
}

std::string FormatTick(double value, double step) {
  if (!std::isfinite(value)) return "";
  if (std::isfinite(step) && step > 0 && std::abs(value) < step * 1e-9) value = 0.0;
  const double magnitude = std::abs(value);
  if (magnitude != 0.0 && (magnitude < 1e-3 || magnitude >= 1e5)) {
    return TidyExponent(General(value, 4));
  }
  int decimals = 0;
  if (std::isfinite(step) && step > 0) {
    decimals = static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
    if (decimals < 0) decimals = 0;
    if (decimals > 8) decimals = 8;
  }
  // Nice steps of 2.5 x 10^k need one decimal more than log10(step) says.
  if (std::isfinite(step) && step > 0) {
    const double scaled = step * std::pow(10.0, decimals);
    if (std::abs(scaled - std::round(scaled)) > 1e-6) ++decimals;
  }
  return Fixed(value, decimals);
}

std::string FormatLogTick(double value) {
  if (!std::isfinite(value) || value <= 0) return "";
  if (value >= 1e-3 && value < 1e5) return TidyExponent(General(value, 6));
  return TidyExponent(General(value, 3));
}

std::string FormatCoordinate(double value) {
  MBOPT_CHECK(std::isfinite(value), "SVG coordinate must be finite");
  std::string s = Fixed(value, 2);
  if (s == "-0.00") s = "0.00";
  return s;
}

}  // namespace mbopt::report
