// Status propagation helpers. Debian 12's Abseil (20220623) ships no status
// macros, so these few are ours. Every fallible call in mbopt returns an
// absl::Status or absl::StatusOr<T>; these keep the happy path readable.
#pragma once

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define MBOPT_CONCAT_INNER_(a, b) a##b
#define MBOPT_CONCAT_(a, b) MBOPT_CONCAT_INNER_(a, b)

// Returns from the enclosing function if `expr` (an absl::Status) is not OK.
#define MBOPT_RETURN_IF_ERROR(expr)                 \
  do {                                              \
    ::absl::Status mbopt_status_ = (expr);          \
    if (!mbopt_status_.ok()) return mbopt_status_;  \
  } while (0)

// `MBOPT_ASSIGN_OR_RETURN(auto x, F());` assigns the value of an
// absl::StatusOr<T> or returns its status from the enclosing function.
#define MBOPT_ASSIGN_OR_RETURN(lhs, expr) \
  MBOPT_ASSIGN_OR_RETURN_IMPL_(MBOPT_CONCAT_(mbopt_statusor_, __LINE__), lhs, expr)
#define MBOPT_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                 \
  if (!tmp.ok()) return tmp.status();                \
  lhs = std::move(tmp).value()
