// absl::Status -> grpc::Status: the one place where a domain error becomes a
// wire error. The canonical codes are the same numbers in both libraries.
#pragma once

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace mbopt::service {

grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace mbopt::service
