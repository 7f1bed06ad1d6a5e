// Number-to-text for the report: table values, axis tick labels and SVG
// coordinates. Locale-independent (std::to_chars): the decimal point is '.'
// whatever setlocale() the program made.
#pragma once

#include <string>

namespace mbopt::report {

// A value for a table cell: `significant` digits, exponent form only for
// very large or small magnitudes. NaN gives `missing`, infinities "inf" /
// "-inf" spelled out.
std::string FormatValue(double value, int significant = 6, const char* missing = "\u2014");

// A tick label for a linear axis whose ticks are `step` apart: enough
// decimals to tell neighbours apart, no trailing noise (0.30000000000000004
// prints as 0.3), exponent form (1e-5, 2.5e6) outside [1e-3, 1e5).
std::string FormatTick(double value, double step);

// A tick label for a logarithmic axis (decades and their 2x, 5x).
std::string FormatLogTick(double value);

// An SVG coordinate with two decimals. Only for finite values: callers drop
// non-finite points before drawing (checked).
std::string FormatCoordinate(double value);

}  // namespace mbopt::report
