// Text and JSON files may hold bytes that are not UTF-8 in a string field;
// the binary message a client sends would then be refused by the server's
// parser with nothing but a log line. The file path refuses them instead,
// naming the field (a finding of tests/fuzz). Every path, the server's
// included, also refuses strings longer than the limits of spec/limits.h:
// a 100 KB study with one long constraint name took a server to 2.4 GB.
#pragma once

#include <google/protobuf/message.h>

#include "spec/io/locator.h"

namespace mbopt::spec::io {

// Adds an error for every string field of `message` (recursively) whose
// bytes are not valid UTF-8.
void CheckUtf8Strings(const google::protobuf::Message& message, const Where& where, Errors* errors);

// Adds an error for every string field of `message` (recursively) longer
// than its limit: kMaxNameBytes for a field called `name`, kMaxStringBytes
// for any other.
void CheckStringLengths(const google::protobuf::Message& message, const Where& where, Errors* errors);

}  // namespace mbopt::spec::io
