#include "server/main/gc_command.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "server/jobs/job_state.h"
#include "server/main/flag_value.h"
#include "server/store/store.h"

namespace mbopt::server_main {
namespace {

constexpr const char* kGcUsage =
    "usage: mbopt-server gc --db PATH [--keep N] [--older-than-days D]\n"
    "                       [--export FILE] [--dry-run]\n"
    "  Deletes finished jobs (converged, max cycles, stalled, failed) with\n"
    "  everything logged for them, then compacts the file. Cancelled and\n"
    "  interrupted jobs can be resumed and are never pruned. Run it while no\n"
    "  server uses the database (the server holds it locked).\n"
    "  --keep N             keep the newest N finished jobs\n"
    "  --older-than-days D  prune only jobs last changed more than D days ago\n"
    "                       (at least one of --keep and --older-than-days)\n"
    "  --export FILE        copy the pruned jobs into the job database FILE\n"
    "                       first (created if missing; `mbopt report --db FILE`\n"
    "                       reads it)\n"
    "  --dry-run            list what would be pruned, change nothing\n";

struct GcFlags {
  std::string db_path;
  std::optional<std::int64_t> keep;
  std::optional<double> older_than_days;
  std::string export_path;
  bool dry_run = false;
};

bool ParseGcFlags(int argc, char** argv, GcFlags* flags) {
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kGcUsage;
      std::exit(0);
    }
    if (arg == "--dry-run") {
      flags->dry_run = true;
      continue;
    }
    std::string name, value;
    if (!FlagValue(argc, argv, &i, &name, &value)) {
      std::cerr << "mbopt-server gc: " << arg << " needs a value\n" << kGcUsage;
      return false;
    }
    if (name == "--db") {
      flags->db_path = value;
    } else if (name == "--export") {
      flags->export_path = value;
    } else if (name == "--keep") {
      std::int64_t n = 0;
      if (!absl::SimpleAtoi(value, &n) || n < 0) {
        std::cerr << "mbopt-server gc: --keep needs an integer >= 0, got '" << value << "'\n";
        return false;
      }
      flags->keep = n;
    } else if (name == "--older-than-days") {
      double days = 0;
      if (!absl::SimpleAtod(value, &days) || !(days >= 0) || days > 1e5) {
        std::cerr << "mbopt-server gc: --older-than-days needs a number of days in [0, 1e5], got '" << value
                  << "'\n";
        return false;
      }
      flags->older_than_days = days;
    } else {
      std::cerr << "mbopt-server gc: unknown option '" << name << "'\n" << kGcUsage;
      return false;
    }
  }
  if (flags->db_path.empty()) {
    std::cerr << "mbopt-server gc: --db PATH is required (the database to prune)\n" << kGcUsage;
    return false;
  }
  if (!flags->keep.has_value() && !flags->older_than_days.has_value()) {
    std::cerr << "mbopt-server gc: say which jobs to prune: --keep N, --older-than-days D, or both\n";
    return false;
  }
  if (!flags->export_path.empty() && flags->export_path == flags->db_path) {
    std::cerr << "mbopt-server gc: --export must name another file than --db\n";
    return false;
  }
  return true;
}

// The database and its WAL, in bytes (what the pruning gives back).
std::int64_t FileBytes(const std::string& db_path) {
  std::int64_t total = 0;
  for (const std::string& path : {db_path, db_path + "-wal"}) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) total += static_cast<std::int64_t>(st.st_size);
  }
  return total;
}

std::string Megabytes(std::int64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

// The finished jobs to prune, oldest first: beyond the newest `keep`
// finished ones, and (if given) unchanged for `older_than_days`.
std::vector<store::JobRow> SelectJobs(const std::vector<store::JobRow>& rows, const GcFlags& flags,
                                      std::int64_t now_unix_ms) {
  std::vector<const store::JobRow*> finished;
  for (const store::JobRow& row : rows) {
    const std::optional<jobs::JobState> state = jobs::ParseJobState(row.state);
    if (state.has_value() && jobs::IsFinished(*state)) finished.push_back(&row);
  }
  std::size_t candidates = finished.size();  // rows are by seq: the newest last
  if (flags.keep.has_value()) {
    const std::size_t keep = static_cast<std::size_t>(*flags.keep);
    candidates = finished.size() > keep ? finished.size() - keep : 0;
  }
  std::vector<store::JobRow> selected;
  for (std::size_t i = 0; i < candidates; ++i) {
    const store::JobRow& row = *finished[i];
    if (flags.older_than_days.has_value()) {
      const double age_days = static_cast<double>(now_unix_ms - row.updated_unix_ms) / 86'400'000.0;
      if (age_days <= *flags.older_than_days) continue;
    }
    selected.push_back(row);
  }
  return selected;
}

}  // namespace

int RunGcCommand(int argc, char** argv) {
  GcFlags flags;
  if (!ParseGcFlags(argc, argv, &flags)) return 2;
  struct stat st {};
  if (::stat(flags.db_path.c_str(), &st) != 0) {
    std::cerr << "mbopt-server gc: no job database at " << flags.db_path << "\n";
    return 1;
  }
  absl::StatusOr<std::unique_ptr<store::Store>> store = store::Store::Open(flags.db_path);
  if (!store.ok()) {
    std::cerr << "mbopt-server gc: " << store.status().message() << "\n";
    return 1;
  }
  absl::StatusOr<std::vector<store::JobRow>> rows = (*store)->ListJobs();
  if (!rows.ok()) {
    std::cerr << "mbopt-server gc: " << rows.status().message() << "\n";
    return 1;
  }
  const std::int64_t now_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  const std::vector<store::JobRow> selected = SelectJobs(*rows, flags, now_ms);
  if (flags.dry_run) {
    for (const store::JobRow& row : selected) {
      std::cout << row.id << "\t" << row.state << "\t" << row.study_name << "\n";
    }
    std::cout << "would prune " << selected.size() << " of " << rows->size() << " jobs\n";
    return 0;
  }
  const std::int64_t bytes_before = FileBytes(flags.db_path);
  if (!flags.export_path.empty() && !selected.empty()) {
    std::vector<std::string> ids;
    for (const store::JobRow& row : selected) ids.push_back(row.id);
    const absl::Status exported = (*store)->ExportJobs(ids, flags.export_path);
    if (!exported.ok()) {
      std::cerr << "mbopt-server gc: nothing pruned: cannot export to " << flags.export_path << ": "
                << exported.message() << "\n";
      return 1;
    }
  }
  // One transaction per job: an interruption leaves whole jobs.
  for (const store::JobRow& row : selected) {
    const absl::Status deleted = (*store)->DeleteJob(row.id);
    if (!deleted.ok()) {
      std::cerr << "mbopt-server gc: cannot delete " << row.id << ": " << deleted.message() << "\n";
      return 1;
    }
  }
  if (!selected.empty()) {
    const absl::Status compacted = (*store)->Compact();
    if (!compacted.ok()) {
      std::cerr << "mbopt-server gc: the jobs are deleted but the file was not compacted: " << compacted.message()
                << "\n";
      return 1;
    }
  }
  std::cout << "pruned " << selected.size() << " of " << rows->size() << " jobs";
  if (!selected.empty()) std::cout << " (" << selected.front().id << " .. " << selected.back().id << ")";
  if (!flags.export_path.empty() && !selected.empty()) std::cout << ", exported to " << flags.export_path;
  std::cout << "; " << flags.db_path << ": " << Megabytes(bytes_before) << " -> "
            << Megabytes(FileBytes(flags.db_path)) << "\n";
  return 0;
}

}  // namespace mbopt::server_main
