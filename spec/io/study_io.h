// spec/io: the boundary where study and scene files (protobuf text format,
// or protobuf JSON when the file name ends in ".json") become validated
// domain types (spec/study.h, spec/scene.h).
//
// Every error is InvalidArgument (NotFound for a missing file) and names the
// file, the line and column where the text has one, the field path (e.g.
// "lumped.elements[2].a.body") and what was expected. Several errors of one
// file are reported together, one per line. Numbers are converted to SI
// here; nothing past this boundary sees a unit.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "mbopt/v1/study.pb.h"
#include "spec/scene.h"
#include "spec/study.h"

namespace mbopt::spec::io {

// Reads and validates a .scene.textproto (or .json).
absl::StatusOr<Scene> LoadSceneFile(const std::string& path);

// Reads and validates a .study.textproto (or .json); a scene_file is
// resolved relative to the study file's directory. The study's
// AnalysisOverrides are applied to the returned study's scene.
absl::StatusOr<Study> LoadStudyFile(const std::string& path);

// The study file as a message with the scene inlined (scene_file replaced by
// the scene), validated like LoadStudyFile: what a client sends to a server.
absl::StatusOr<v1::Study> ReadStudyProto(const std::string& path);

// The same from text already in memory (the format follows `source_name`,
// as for files), for a study with its scene inline: a scene_file is refused.
// What the fuzzing targets (tests/fuzz) drive.
absl::StatusOr<v1::Study> ParseStudyText(const std::string& text, const std::string& source_name);
absl::StatusOr<Scene> ParseSceneText(const std::string& text, const std::string& source_name);

// Validates a study message that has its scene inlined (a server's input).
// `source_name` names it in messages (there are no line numbers).
absl::StatusOr<Study> StudyFromProto(const v1::Study& study, const std::string& source_name);
absl::StatusOr<Scene> SceneFromProto(const v1::Scene& scene, const std::string& source_name);

}  // namespace mbopt::spec::io
