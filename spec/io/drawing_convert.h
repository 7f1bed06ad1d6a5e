// spec::SceneDrawing to and from its file schema (mbopt.v1.SceneDrawing,
// proto/mbopt/v1/drawing.proto): the worker writes the file, the client
// reads it back.
#pragma once

#include "absl/status/statusor.h"
#include "mbopt/v1/drawing.pb.h"
#include "spec/scene_drawing.h"

namespace mbopt::spec::io {

v1::SceneDrawing DrawingToProto(const SceneDrawing& drawing);

// InvalidArgument naming the part and field when an index points past the
// point table or an instant holds another number of points.
absl::StatusOr<SceneDrawing> DrawingFromProto(const v1::SceneDrawing& message);

}  // namespace mbopt::spec::io
