#include "server/jobs/record_codec.h"

#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace mbopt::jobs {
namespace {

// 2: optimality_residual after max_approximation_error's row.
// 3: restoration after converged. Records of version 2 are still read
// (restoration false): a database written before it resumes as it was.
// 4: the records of a design set, with their constraint_violations and
// failure_kind after restoration. Only such records are written as 4: an optimization's records
// stay version 3 byte for byte, so a job logged before resumes (its replay
// compares the bytes).
// 5: the records of a Pareto front's points: a design set's record and the
// point's level, value, run state, cycles and analyses. Only those are
// written as 5, so a design set logged before resumes byte for byte.
// 6: a cycle record of a Pareto point's run: an optimization's record (the
// fields of 3) and the point's number. Only those are written as 6.
// 7: a point of a front of three objectives: the fields of 5 and the third
// objective's level and value. Only those are written as 7.
constexpr unsigned char kVersion = 7;
constexpr unsigned char kParetoThreeVersion = 7;
constexpr unsigned char kParetoRunVersion = 6;
constexpr unsigned char kParetoPointVersion = 5;
constexpr unsigned char kDesignSetVersion = 4;
constexpr unsigned char kOptimizationVersion = 3;
constexpr unsigned char kOldestReadVersion = 2;

class Writer {
 public:
  void U64(std::uint64_t v) {
    for (int b = 0; b < 8; ++b) out_.push_back(static_cast<char>((v >> (8 * b)) & 0xffu));
  }
  void U32(std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out_.push_back(static_cast<char>((v >> (8 * b)) & 0xffu));
  }
  void Int(int v) { U32(static_cast<std::uint32_t>(v)); }
  void Int64(std::int64_t v) { U64(static_cast<std::uint64_t>(v)); }
  void Bool(bool v) { out_.push_back(v ? 1 : 0); }
  void Double(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    U64(bits);
  }
  void String(const std::string& s) {
    U32(static_cast<std::uint32_t>(s.size()));
    out_ += s;
  }
  void Vector(const Eigen::VectorXd& v) {
    U32(static_cast<std::uint32_t>(v.size()));
    for (Eigen::Index i = 0; i < v.size(); ++i) Double(v[i]);
  }
  void Bools(const std::vector<bool>& v) {
    U32(static_cast<std::uint32_t>(v.size()));
    for (bool b : v) Bool(b);
  }
  std::string& out() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  bool ok() const { return ok_; }
  bool at_end() const { return pos_ == in_.size(); }
  std::uint64_t U64() { return Bytes(8); }
  std::uint32_t U32() { return static_cast<std::uint32_t>(Bytes(4)); }
  int Int() { return static_cast<int>(U32()); }
  std::int64_t Int64() { return static_cast<std::int64_t>(U64()); }
  bool Bool() { return Bytes(1) != 0; }
  double Double() {
    const std::uint64_t bits = U64();
    double v = 0;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  std::string String() {
    const std::uint32_t n = U32();
    if (!Need(n)) return {};
    std::string s = in_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  Eigen::VectorXd Vector() {
    const std::uint32_t n = U32();
    if (!Need(static_cast<size_t>(n) * 8)) return {};
    Eigen::VectorXd v(n);
    for (std::uint32_t i = 0; i < n; ++i) v[i] = Double();
    return v;
  }
  std::vector<bool> Bools() {
    const std::uint32_t n = U32();
    if (!Need(n)) return {};
    std::vector<bool> v(n);
    for (std::uint32_t i = 0; i < n; ++i) v[i] = Bool();
    return v;
  }

 private:
  bool Need(size_t n) {
    if (!ok_ || in_.size() - pos_ < n) ok_ = false;
    return ok_;
  }
  std::uint64_t Bytes(int n) {
    if (!Need(static_cast<size_t>(n))) return 0;
    std::uint64_t v = 0;
    for (int b = 0; b < n; ++b) {
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(in_[pos_ + static_cast<size_t>(b)])) << (8 * b);
    }
    pos_ += static_cast<size_t>(n);
    return v;
  }
  const std::string& in_;
  size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace

std::string EncodeCycleRecord(const slp::CycleRecord& r) {
  Writer w;
  w.out().push_back(static_cast<char>(r.pareto_point > 0 ? kParetoRunVersion
                                      : r.pareto_three   ? kParetoThreeVersion
                                      : r.pareto         ? kParetoPointVersion
                                      : r.design_set     ? kDesignSetVersion
                                                         : kOptimizationVersion));
  w.Int(r.cycle);
  w.Int(r.attempt);
  w.Bool(r.accepted);
  w.String(r.rejection_reason);
  w.Vector(r.x0);
  w.Vector(r.x_trial);
  w.Double(r.objective_x0);
  w.Double(r.objective_trial);
  w.Double(r.objective_predicted);
  w.Double(r.max_violation_x0);
  w.Double(r.max_violation_trial);
  w.Int(r.worst_constraint_trial);
  w.Double(r.objective_error);
  w.Double(r.max_approximation_error);
  w.Int(r.worst_approximation_row);
  w.Double(r.optimality_residual);
  w.Bool(r.lp_feasible);
  w.Double(r.infeasibility);
  w.String(r.lp_status);
  w.Int(r.lp_iterations);
  w.Int(r.rows_screened_in);
  w.Vector(r.move_limits);
  w.Vector(r.move_limits_next);
  w.Bools(r.on_move_limit);
  w.Bools(r.on_bound);
  w.Int64(r.analyses_total);
  w.Bool(r.converged);
  w.Bool(r.restoration);
  if (r.design_set || r.pareto) {  // a Pareto point is a design set's record and more
    w.U32(static_cast<std::uint32_t>(r.constraint_violations.size()));
    for (double v : r.constraint_violations) w.Double(v);
    w.String(r.failure_kind);
  }
  if (r.pareto) {
    w.Double(r.pareto_level_si);
    w.Double(r.pareto_value_si);
    w.String(r.pareto_state);
    w.Int(r.pareto_cycles);
    w.Int64(r.pareto_analyses);
  }
  if (r.pareto_three) {
    w.Double(r.pareto_level3_si);
    w.Double(r.pareto_value3_si);
  }
  if (r.pareto_point > 0) w.Int(r.pareto_point);
  return std::move(w.out());
}

absl::StatusOr<slp::CycleRecord> DecodeCycleRecord(const std::string& bytes) {
  const unsigned char version = bytes.empty() ? 0 : static_cast<unsigned char>(bytes[0]);
  if (version < kOldestReadVersion || version > kVersion) {
    return absl::DataLossError(absl::StrCat("a cycle record of ", bytes.size(),
                                            " bytes does not start with a format version from ",
                                            kOldestReadVersion, " to ", kVersion));
  }
  const std::string body = bytes.substr(1);
  Reader r(body);
  slp::CycleRecord c;
  c.cycle = r.Int();
  c.attempt = r.Int();
  c.accepted = r.Bool();
  c.rejection_reason = r.String();
  c.x0 = r.Vector();
  c.x_trial = r.Vector();
  c.objective_x0 = r.Double();
  c.objective_trial = r.Double();
  c.objective_predicted = r.Double();
  c.max_violation_x0 = r.Double();
  c.max_violation_trial = r.Double();
  c.worst_constraint_trial = r.Int();
  c.objective_error = r.Double();
  c.max_approximation_error = r.Double();
  c.worst_approximation_row = r.Int();
  c.optimality_residual = r.Double();
  c.lp_feasible = r.Bool();
  c.infeasibility = r.Double();
  c.lp_status = r.String();
  c.lp_iterations = r.Int();
  c.rows_screened_in = r.Int();
  c.move_limits = r.Vector();
  c.move_limits_next = r.Vector();
  c.on_move_limit = r.Bools();
  c.on_bound = r.Bools();
  c.analyses_total = r.Int64();
  c.converged = r.Bool();
  if (version >= 3) c.restoration = r.Bool();
  if (version == kParetoRunVersion) {
    c.pareto_point = r.Int();
  } else if (version >= kDesignSetVersion) {
    c.design_set = true;
    const Eigen::VectorXd violations = r.Vector();
    c.constraint_violations.assign(violations.data(), violations.data() + violations.size());
    c.failure_kind = r.String();
  }
  if (version == kParetoPointVersion || version == kParetoThreeVersion) {
    c.pareto = true;
    c.pareto_level_si = r.Double();
    c.pareto_value_si = r.Double();
    c.pareto_state = r.String();
    c.pareto_cycles = r.Int();
    c.pareto_analyses = r.Int64();
  }
  if (version == kParetoThreeVersion) {
    c.pareto_three = true;
    c.pareto_level3_si = r.Double();
    c.pareto_value3_si = r.Double();
  }
  if (!r.ok() || !r.at_end()) {
    return absl::DataLossError(absl::StrCat("a cycle record of ", bytes.size(), " bytes is truncated or too long"));
  }
  return c;
}

}  // namespace mbopt::jobs
