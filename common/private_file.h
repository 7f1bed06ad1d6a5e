// Whether a file that holds a secret (a private key, a token, the server's
// token table) is kept from the other users of the machine. Refused, as ssh
// refuses a private key that others can read:
//   - any access by others (mode bits 0007): they could read the secret, or
//     write one of their own (a token table to which anyone may add an admin
//     token's hash);
//   - writing by the group (0020);
//   - reading by the group (0040), unless the group is this process's own
//     effective group: a Kubernetes secret with `fsGroup` is mounted root-owned
//     and group-readable by the pod's group, and a file `root:mbopt 0640` is
//     how a service's user reads what root keeps.
// The owner is not checked, for the same two cases. Symbolic links are
// followed (Kubernetes mounts secrets through them): the mode of the file
// read counts.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt {

// The mode bits that make `mode` unsafe for a secret file whose group is
// `file_group` read by a process of effective group `process_group`; 0 when
// it is safe.
inline unsigned UnsafeSecretModeBits(unsigned mode, unsigned file_group, unsigned process_group) {
  unsigned unsafe = mode & (S_IRWXO | S_IWGRP | S_IXGRP);
  if ((mode & S_IRGRP) != 0 && file_group != process_group) unsafe |= S_IRGRP;
  return unsafe;
}

// OK when `path` is kept from others (see above). FailedPrecondition naming
// `what` (e.g. "the token table"), the path, its mode, who may do what with
// it, and the chmod that fixes it. NotFound when it cannot be looked at.
inline absl::Status CheckSecretFileMode(const std::string& path, const std::string& what) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    return absl::NotFoundError(absl::StrCat("cannot read ", what, " ", path, ": ", std::strerror(errno)));
  }
  const unsigned mode = info.st_mode & 07777;
  const unsigned unsafe = UnsafeSecretModeBits(mode, info.st_gid, ::getegid());
  if (unsafe == 0) return absl::OkStatus();
  const bool others = (unsafe & S_IRWXO) != 0;
  const bool readable = (unsafe & (S_IROTH | S_IRGRP)) != 0;
  const bool writable = (unsafe & (S_IWOTH | S_IWGRP)) != 0;
  char mode_text[8];
  std::snprintf(mode_text, sizeof mode_text, "%04o", mode);
  return absl::FailedPreconditionError(absl::StrCat(
      what, " ", path, " has mode ", mode_text, ": ", readable ? "readable" : "", readable && writable ? " and " : "",
      writable ? "writable" : "", readable || writable ? " by " : "usable by ",
      others ? "every user of this machine" : "its group", "; it holds a secret and is refused. Run `chmod 600 ",
      path, "` (or `chmod 640` with the file's group the one this program runs as)"));
}

}  // namespace mbopt
