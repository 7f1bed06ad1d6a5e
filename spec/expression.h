// Arithmetic expressions for numbers in scene files, e.g.
// `expr: "wheelbase / speed"` or `expr: "-rod_length / 2"`: parsed once when
// the scene is loaded (names resolved to parameter indices), evaluated per
// analysis from the SI parameter values. Expressions work in SI: a parameter
// contributes its SI value whatever unit the file gives it.
//
// Grammar: + - * / ^ (power, right-associative, binds tighter than unary
// minus: -a^2 = -(a^2)), parentheses, numbers (1e-3), parameter names, the
// constant pi, and the functions sqrt, sin, cos, tan, asin, acos, atan, exp,
// log, abs (one argument) and atan2, min, max, pow (two). Pure.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::spec {

class Expression {
 public:
  // Finds a parameter's index by name (nullopt: no such parameter) and lists
  // the names, for "did you mean" messages.
  struct Names {
    std::function<std::optional<int>(const std::string&)> find;
    std::vector<std::string> all;
    std::string kind = "parameter";  // what a name is, for messages
    // Names found by `find` that stand for an expression of other names (a
    // parameter written as `expr`): their code is put in place of the name,
    // so the result reads only plain names and its derivatives are those of
    // the whole. Returns nullptr for a plain name, an error to refuse the
    // name (a cycle). The inlined code's name indices are scene parameter
    // indices, shifted by `expand_index_offset` (a response numbers
    // parameters after its signals).
    std::function<absl::StatusOr<std::shared_ptr<const Expression>>(const std::string&)> expand;
    int expand_index_offset = 0;
  };
  // InvalidArgument "column N: <what was expected>" (1-based), or naming the
  // unknown parameter with the nearest known names.
  static absl::StatusOr<std::shared_ptr<const Expression>> Parse(const std::string& text, const Names& names);

  double Evaluate(const std::vector<double>& parameter_values_si) const;
  // The value, and in `partials` (resized to parameters().size()) its
  // derivatives with respect to each parameter read, in parameters()'s
  // order: forward-mode differentiation of the code, exact up to rounding.
  // abs, min and max take the derivative of the branch taken (abs: 0 at 0).
  double EvaluateWithPartials(const std::vector<double>& parameter_values_si, std::vector<double>* partials) const;
  // Indices of the parameters it reads (sorted, unique).
  const std::vector<int>& parameters() const { return parameters_; }
  const std::string& text() const { return text_; }

  // Reverse Polish code: the evaluator runs it on a small stack.
  enum class Op { kConstant, kParameter, kNegate, kAdd, kSubtract, kMultiply, kDivide, kPower, kFunction1, kFunction2 };
  struct Instruction {
    Op op;
    double value = 0.0;  // kConstant
    int index = 0;       // kParameter: parameter; kFunction*: function
  };

 private:
  std::string text_;
  std::vector<Instruction> code_;
  std::vector<int> parameters_;
  int max_stack_ = 0;
  friend class ExpressionParser;
};

}  // namespace mbopt::spec
