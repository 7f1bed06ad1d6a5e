#include "spec/expression.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace mbopt::spec {
namespace {

// Expressions in files are short; a fixed evaluation stack avoids
// allocation, and Parse refuses what would not fit.
constexpr int kMaxEvaluationStack = 64;

struct Function {
  const char* name;
  int arity;
  double (*one)(double);
  double (*two)(double, double);
};

const std::array<Function, 14> kFunctions = {{
    {"sqrt", 1, [](double x) { return std::sqrt(x); }, nullptr},
    {"sin", 1, [](double x) { return std::sin(x); }, nullptr},
    {"cos", 1, [](double x) { return std::cos(x); }, nullptr},
    {"tan", 1, [](double x) { return std::tan(x); }, nullptr},
    {"asin", 1, [](double x) { return std::asin(x); }, nullptr},
    {"acos", 1, [](double x) { return std::acos(x); }, nullptr},
    {"atan", 1, [](double x) { return std::atan(x); }, nullptr},
    {"exp", 1, [](double x) { return std::exp(x); }, nullptr},
    {"log", 1, [](double x) { return std::log(x); }, nullptr},
    {"abs", 1, [](double x) { return std::abs(x); }, nullptr},
    {"atan2", 2, nullptr, [](double y, double x) { return std::atan2(y, x); }},
    {"min", 2, nullptr, [](double a, double b) { return std::min(a, b); }},
    {"max", 2, nullptr, [](double a, double b) { return std::max(a, b); }},
    {"pow", 2, nullptr, [](double a, double b) { return std::pow(a, b); }},
}};

// Levenshtein distance, for "did you mean".
size_t Distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

class ExpressionParser {
 public:
  ExpressionParser(const std::string& text, const Expression::Names& names) : text_(text), names_(names) {}

  absl::StatusOr<std::shared_ptr<const Expression>> Run() {
    auto e = std::make_shared<Expression>();
    e->text_ = text_;
    out_ = e.get();
    if (absl::Status s = Sum(); !s.ok()) return s;
    Skip();
    if (pos_ < text_.size()) return Error("an operator or the end of the expression");
    std::sort(e->parameters_.begin(), e->parameters_.end());
    e->parameters_.erase(std::unique(e->parameters_.begin(), e->parameters_.end()), e->parameters_.end());
    if (max_depth_ > kMaxEvaluationStack) {
      return absl::InvalidArgumentError(absl::StrCat("\"", text_, "\" is nested too deeply to evaluate (",
                                                     max_depth_, " pending values, at most ", kMaxEvaluationStack,
                                                     ")"));
    }
    e->max_stack_ = max_depth_;
    return std::shared_ptr<const Expression>(std::move(e));
  }

 private:
  void Skip() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  absl::Status Error(const std::string& expected) const {
    return absl::InvalidArgumentError(absl::StrCat("column ", pos_ + 1, " of \"", text_, "\": expected ", expected));
  }
  void Emit(Expression::Op op, double value = 0.0, int index = 0, int stack_change = 0) {
    out_->code_.push_back({op, value, index});
    depth_ += stack_change;
    max_depth_ = std::max(max_depth_, depth_);
  }

  absl::Status Sum() {
    if (absl::Status s = Product(); !s.ok()) return s;
    while (true) {
      Skip();
      if (pos_ >= text_.size() || (text_[pos_] != '+' && text_[pos_] != '-')) return absl::OkStatus();
      const char op = text_[pos_++];
      if (absl::Status s = Product(); !s.ok()) return s;
      Emit(op == '+' ? Expression::Op::kAdd : Expression::Op::kSubtract, 0, 0, -1);
    }
  }
  absl::Status Product() {
    if (absl::Status s = Unary(); !s.ok()) return s;
    while (true) {
      Skip();
      if (pos_ >= text_.size() || (text_[pos_] != '*' && text_[pos_] != '/')) return absl::OkStatus();
      const char op = text_[pos_++];
      if (absl::Status s = Unary(); !s.ok()) return s;
      Emit(op == '*' ? Expression::Op::kMultiply : Expression::Op::kDivide, 0, 0, -1);
    }
  }
  // Every nesting (parentheses, signs, powers, arguments) passes here: the
  // parser's recursion is bounded before the machine's stack is.
  absl::Status Unary() {
    if (nesting_ >= 4 * kMaxEvaluationStack) return Error("less nesting (parentheses, signs or powers)");
    ++nesting_;
    absl::Status s = UnaryBody();
    --nesting_;
    return s;
  }
  absl::Status UnaryBody() {
    Skip();
    if (pos_ < text_.size() && (text_[pos_] == '-' || text_[pos_] == '+')) {
      const char op = text_[pos_++];
      if (absl::Status s = Unary(); !s.ok()) return s;
      if (op == '-') Emit(Expression::Op::kNegate);
      return absl::OkStatus();
    }
    return Power();
  }
  absl::Status Power() {
    if (absl::Status s = Primary(); !s.ok()) return s;
    Skip();
    if (pos_ < text_.size() && text_[pos_] == '^') {
      ++pos_;
      if (absl::Status s = Unary(); !s.ok()) return s;  // right-associative: a^b^c = a^(b^c)
      Emit(Expression::Op::kPower, 0, 0, -1);
    }
    return absl::OkStatus();
  }
  absl::Status Primary() {
    Skip();
    if (pos_ >= text_.size()) return Error(absl::StrCat("a number, a name (", names_.kind, "), a function or '('"));
    const char c = text_[pos_];
    if (c == '(') {
      ++pos_;
      if (absl::Status s = Sum(); !s.ok()) return s;
      Skip();
      if (pos_ >= text_.size() || text_[pos_] != ')') return Error("')'");
      ++pos_;
      return absl::OkStatus();
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      const char* start = text_.c_str() + pos_;
      char* end = nullptr;
      const double value = std::strtod(start, &end);
      if (end == start) return Error("a number");
      pos_ += static_cast<size_t>(end - start);
      Emit(Expression::Op::kConstant, value, 0, 1);
      return absl::OkStatus();
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = pos_;
      // A dot followed by a letter continues a name: "<case>.<output>".
      auto name_char = [&](size_t at) {
        const unsigned char ch = static_cast<unsigned char>(text_[at]);
        if (std::isalnum(ch) || ch == '_') return true;
        return ch == '.' && at + 1 < text_.size() &&
               (std::isalpha(static_cast<unsigned char>(text_[at + 1])) || text_[at + 1] == '_');
      };
      while (pos_ < text_.size() && name_char(pos_)) ++pos_;
      const std::string name = text_.substr(start, pos_ - start);
      Skip();
      if (pos_ < text_.size() && text_[pos_] == '(') return Call(name, start);
      if (std::optional<int> index = names_.find(name); index.has_value()) {
        if (names_.expand) {
          absl::StatusOr<std::shared_ptr<const Expression>> expansion = names_.expand(name);
          if (!expansion.ok()) {
            return absl::InvalidArgumentError(
                absl::StrCat("column ", start + 1, " of \"", text_, "\": ", expansion.status().message()));
          }
          if (*expansion != nullptr) {
            Inline(**expansion);
            return absl::OkStatus();
          }
        }
        Emit(Expression::Op::kParameter, 0, *index, 1);
        out_->parameters_.push_back(*index);
        return absl::OkStatus();
      }
      if (name == "pi") {
        Emit(Expression::Op::kConstant, std::numbers::pi, 0, 1);
        return absl::OkStatus();
      }
      std::vector<std::string> near;
      for (const std::string& known : names_.all) {
        if (Distance(known, name) <= 2) near.push_back(known);
      }
      return absl::InvalidArgumentError(absl::StrCat(
          "column ", start + 1, " of \"", text_, "\": unknown ", names_.kind, " \"", name, "\"",
          near.empty() ? "" : absl::StrCat(" (did you mean ", absl::StrJoin(near, ", "), "?)")));
    }
    return Error(absl::StrCat("a number, a name (", names_.kind, "), a function or '('"));
  }
  absl::Status Call(const std::string& name, size_t start) {
    int function = -1;
    for (size_t f = 0; f < kFunctions.size(); ++f) {
      if (name == kFunctions[f].name) function = static_cast<int>(f);
    }
    if (function < 0) {
      pos_ = start;
      return Error(absl::StrCat("a function (sqrt, sin, cos, tan, asin, acos, atan, atan2, exp, log, abs, min, ",
                                "max, pow), not \"", name, "\""));
    }
    ++pos_;  // '('
    const int arity = kFunctions[static_cast<size_t>(function)].arity;
    for (int a = 0; a < arity; ++a) {
      if (absl::Status s = Sum(); !s.ok()) return s;
      Skip();
      const char expected = a + 1 < arity ? ',' : ')';
      if (pos_ >= text_.size() || text_[pos_] != expected) {
        return Error(absl::StrCat("'", std::string(1, expected), "' (", name, " takes ", arity, " argument",
                                  arity > 1 ? "s" : "", ")"));
      }
      ++pos_;
    }
    Emit(arity == 1 ? Expression::Op::kFunction1 : Expression::Op::kFunction2, 0, function, arity == 1 ? 0 : -1);
    return absl::OkStatus();
  }

  // The code of `e` where a name stood: it leaves one value on the stack,
  // needing e.max_stack_ above what is there.
  void Inline(const Expression& e) {
    for (Expression::Instruction in : e.code_) {
      if (in.op == Expression::Op::kParameter) in.index += names_.expand_index_offset;
      out_->code_.push_back(in);
    }
    for (int p : e.parameters_) out_->parameters_.push_back(p + names_.expand_index_offset);
    max_depth_ = std::max(max_depth_, depth_ + e.max_stack_);
    depth_ += 1;
  }

  const std::string& text_;
  const Expression::Names& names_;
  Expression* out_ = nullptr;
  size_t pos_ = 0;
  int depth_ = 0, max_depth_ = 0;
  int nesting_ = 0;
};

absl::StatusOr<std::shared_ptr<const Expression>> Expression::Parse(const std::string& text, const Names& names) {
  return ExpressionParser(text, names).Run();
}

double Expression::Evaluate(const std::vector<double>& p) const {
  constexpr int kMaxStack = kMaxEvaluationStack;
  double stack[kMaxStack];
  if (max_stack_ > kMaxStack) return NAN;
  int top = -1;
  for (const Instruction& in : code_) {
    switch (in.op) {
      case Op::kConstant: stack[++top] = in.value; break;
      case Op::kParameter: stack[++top] = p[static_cast<size_t>(in.index)]; break;
      case Op::kNegate: stack[top] = -stack[top]; break;
      case Op::kAdd: --top; stack[top] += stack[top + 1]; break;
      case Op::kSubtract: --top; stack[top] -= stack[top + 1]; break;
      case Op::kMultiply: --top; stack[top] *= stack[top + 1]; break;
      case Op::kDivide: --top; stack[top] /= stack[top + 1]; break;
      case Op::kPower: --top; stack[top] = std::pow(stack[top], stack[top + 1]); break;
      case Op::kFunction1: stack[top] = kFunctions[static_cast<size_t>(in.index)].one(stack[top]); break;
      case Op::kFunction2:
        --top;
        stack[top] = kFunctions[static_cast<size_t>(in.index)].two(stack[top], stack[top + 1]);
        break;
    }
  }
  return top == 0 ? stack[0] : NAN;
}

namespace {

// d f(a) / d a for the one-argument functions, in kFunctions' order.
double Derivative1(int function, double a) {
  switch (function) {
    case 0: return 0.5 / std::sqrt(a);
    case 1: return std::cos(a);
    case 2: return -std::sin(a);
    case 3: return 1.0 / (std::cos(a) * std::cos(a));
    case 4: return 1.0 / std::sqrt(1.0 - a * a);
    case 5: return -1.0 / std::sqrt(1.0 - a * a);
    case 6: return 1.0 / (1.0 + a * a);
    case 7: return std::exp(a);
    case 8: return 1.0 / a;
    case 9: return a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : 0.0;
    default: return NAN;
  }
}

// d f(a, b) / d a and d f(a, b) / d b for the two-argument functions.
std::pair<double, double> Derivative2(int function, double a, double b, double value) {
  switch (function) {
    case 10: {  // atan2(y = a, x = b)
      const double r2 = a * a + b * b;
      return {b / r2, -a / r2};
    }
    case 11: return a <= b ? std::pair{1.0, 0.0} : std::pair{0.0, 1.0};
    case 12: return a >= b ? std::pair{1.0, 0.0} : std::pair{0.0, 1.0};
    case 13: return {b * std::pow(a, b - 1.0), a > 0.0 ? value * std::log(a) : 0.0};
    default: return {NAN, NAN};
  }
}

}  // namespace

double Expression::EvaluateWithPartials(const std::vector<double>& p, std::vector<double>* partials) const {
  const size_t m = parameters_.size();
  partials->assign(m, 0.0);
  constexpr int kMaxStack = kMaxEvaluationStack;
  if (max_stack_ > kMaxStack) {
    partials->assign(m, NAN);
    return NAN;
  }
  // Each stack entry carries its value and its m partials.
  double value[kMaxStack];
  std::vector<double> grad(static_cast<size_t>(max_stack_ + 1) * std::max<size_t>(m, 1), 0.0);
  auto g = [&](int slot) { return grad.data() + static_cast<size_t>(slot) * m; };
  // a := ca * a + cb * b, for the partials of two stack entries.
  auto combine = [&](int a, double ca, int b, double cb) {
    double* ga = g(a);
    const double* gb = g(b);
    // A partial that is exactly 0 stays out: 0 * inf (sqrt'(0) of a
    // subexpression that does not depend on parameter k) is no NaN.
    for (size_t k = 0; k < m; ++k) ga[k] = (ga[k] != 0.0 ? ca * ga[k] : 0.0) + (gb[k] != 0.0 ? cb * gb[k] : 0.0);
  };
  auto scale = [&](int a, double c) {
    double* ga = g(a);
    for (size_t k = 0; k < m; ++k) ga[k] = ga[k] != 0.0 ? c * ga[k] : 0.0;
  };
  int top = -1;
  for (const Instruction& in : code_) {
    switch (in.op) {
      case Op::kConstant:
        value[++top] = in.value;
        std::fill(g(top), g(top) + m, 0.0);
        break;
      case Op::kParameter: {
        value[++top] = p[static_cast<size_t>(in.index)];
        std::fill(g(top), g(top) + m, 0.0);
        const size_t k = static_cast<size_t>(
            std::lower_bound(parameters_.begin(), parameters_.end(), in.index) - parameters_.begin());
        g(top)[k] = 1.0;
        break;
      }
      case Op::kNegate:
        value[top] = -value[top];
        scale(top, -1.0);
        break;
      case Op::kAdd:
        --top;
        value[top] += value[top + 1];
        combine(top, 1.0, top + 1, 1.0);
        break;
      case Op::kSubtract:
        --top;
        value[top] -= value[top + 1];
        combine(top, 1.0, top + 1, -1.0);
        break;
      case Op::kMultiply: {
        --top;
        const double a = value[top], b = value[top + 1];
        value[top] = a * b;
        combine(top, b, top + 1, a);
        break;
      }
      case Op::kDivide: {
        --top;
        const double a = value[top], b = value[top + 1];
        value[top] = a / b;
        combine(top, 1.0 / b, top + 1, -a / (b * b));
        break;
      }
      case Op::kPower: {
        --top;
        const double a = value[top], b = value[top + 1];
        value[top] = std::pow(a, b);
        const auto [da, db] = Derivative2(13, a, b, value[top]);
        // An exponent that depends on nothing contributes nothing, even
        // where log(a) is not defined.
        combine(top, da, top + 1, db);
        break;
      }
      case Op::kFunction1: {
        const double a = value[top];
        value[top] = kFunctions[static_cast<size_t>(in.index)].one(a);
        scale(top, Derivative1(in.index, a));
        break;
      }
      case Op::kFunction2: {
        --top;
        const double a = value[top], b = value[top + 1];
        value[top] = kFunctions[static_cast<size_t>(in.index)].two(a, b);
        const auto [da, db] = Derivative2(in.index, a, b, value[top]);
        combine(top, da, top + 1, db);
        break;
      }
    }
  }
  if (top != 0) {
    partials->assign(m, NAN);
    return NAN;
  }
  std::copy(g(0), g(0) + m, partials->begin());
  return value[0];
}

}  // namespace mbopt::spec
