// The headers every boundary library's units parse before their own code:
// Protobuf's and gRPC's, and the generated messages. Parsed once, into the
// precompiled header that the libraries linking mbopt_proto share
// (mbopt_precompile_proto_headers in cmake/MbOptTargets.cmake): these
// headers are most of the front end's work in those units. Not included by
// any source file; a unit still includes what it uses, so that it builds
// without the precompiled header (MBOPT_PRECOMPILED_HEADERS=OFF).
#pragma once

#include <google/protobuf/arena.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/repeated_field.h>
#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>

#include "mbopt/v1/drawing.pb.h"
#include "mbopt/v1/drivers.pb.h"
#include "mbopt/v1/scene.pb.h"
#include "mbopt/v1/series.pb.h"
#include "mbopt/v1/service.grpc.pb.h"
#include "mbopt/v1/service.pb.h"
#include "mbopt/v1/study.pb.h"
