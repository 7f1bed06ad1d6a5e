// A prepared SQLite statement with RAII and statuses: the only place the
// store turns SQLite result codes into absl::Status.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

struct sqlite3;
struct sqlite3_stmt;

namespace mbopt::store {

// Maps a SQLite result code (with the connection's message) to a status:
// corruption -> DataLoss, "not a database" -> FailedPrecondition, busy or
// locked -> Unavailable, I/O and full disk -> Unavailable, else Internal.
absl::Status SqliteStatus(sqlite3* db, int code, const std::string& what);

// Runs SQL without results (may hold several statements).
absl::Status Exec(sqlite3* db, const std::string& sql);

// Runs `body` inside BEGIN IMMEDIATE .. COMMIT, rolling back on any error.
template <typename Body>
absl::Status InTransaction(sqlite3* db, Body body) {
  absl::Status status = Exec(db, "BEGIN IMMEDIATE");
  if (!status.ok()) return status;
  status = body();
  if (status.ok()) status = Exec(db, "COMMIT");
  if (!status.ok()) (void)Exec(db, "ROLLBACK");
  return status;
}

class Statement {
 public:
  static absl::StatusOr<Statement> Prepare(sqlite3* db, const std::string& sql);
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&&) = delete;
  Statement(const Statement&) = delete;
  ~Statement();

  // Parameters are 1-based, as in SQLite.
  void BindInt(int index, std::int64_t value);
  void BindDouble(int index, double value);
  void BindText(int index, const std::string& value);
  void BindBlob(int index, const std::string& value);

  // true: a row is available; false: done.
  absl::StatusOr<bool> Step();
  // Runs to completion, expecting no rows.
  absl::Status Run();
  // Makes the statement ready to run again with new bindings.
  void Reset();

  // Columns are 0-based, as in SQLite.
  std::int64_t ColumnInt(int index) const;
  double ColumnDouble(int index) const;
  std::string ColumnText(int index) const;
  std::string ColumnBlob(int index) const;

 private:
  Statement(sqlite3* db, sqlite3_stmt* stmt, std::string sql);
  sqlite3* db_;
  sqlite3_stmt* stmt_;
  std::string sql_;
};

}  // namespace mbopt::store
