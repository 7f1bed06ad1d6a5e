// Cells of the plain tables the CLI prints for jobs of several designs
// (design sets, Pareto fronts): a record's values as text, and the rows laid
// out in columns. Pure formatting.
#pragma once

#include <string>
#include <vector>

#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// "%.7g", or `missing` for a value the analysis did not give (not finite).
std::string CellValue(double v, const char* missing);
// Design variable i of the record's trial point, physical; NaN when absent.
double TrialPhysical(const v1::CycleRecord& r, int i);
// Constraint c's largest (g - limit) / scale in the record; NaN when absent.
double ConstraintViolation(const v1::CycleRecord& r, int c);
// Every column as wide as its widest cell, right-aligned, the last column
// left-aligned after two spaces; one line per row, each ending in '\n'.
std::string AlignedRows(const std::vector<std::vector<std::string>>& rows);

}  // namespace mbopt::client
