// Text and JSON files may hold bytes that are not UTF-8 in a string field;
// the binary message a client sends would then be refused by the server's
// parser with nothing but a log line. The file path refuses them instead,
// naming the field (a finding of tests/fuzz).
#pragma once

#include <google/protobuf/message.h>

#include "spec/io/locator.h"

namespace mbopt::spec::io {

// Adds an error for every string field of `message` (recursively) whose
// bytes are not valid UTF-8.
void CheckUtf8Strings(const google::protobuf::Message& message, const Where& where, Errors* errors);

}  // namespace mbopt::spec::io
